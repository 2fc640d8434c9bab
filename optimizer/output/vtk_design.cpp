#include "optimizer/output/vtk_design.hpp"

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "optimizer/batch/sampling.hpp"
#include "optimizer/output/batch_table.hpp"
#include "optimizer/output/tables.hpp"

namespace beamrail {

namespace fs = std::filesystem;

namespace {

// A whole non-negative decimal integer, or -1.
long whole_number(const std::string& text) {
  if (text.empty() || text.size() > 12 || text.find_first_not_of("0123456789") != text.npos)
    return -1;
  return std::strtol(text.c_str(), nullptr, 10);
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string describe(const DesignChoice& c) {
  switch (c.kind) {
    case DesignChoice::Kind::kBest:
      return "the best design";
    case DesignChoice::Kind::kSweepRow:
      return "design " + std::to_string(c.index);
    case DesignChoice::Kind::kHistoryRow:
      return "design " + std::to_string(c.start) + ":" + std::to_string(c.evaluation);
    case DesignChoice::Kind::kOwn:
    case DesignChoice::Kind::kNone:
      break;
  }
  return "the study's own design";
}

}  // namespace

std::string choose_design(const Study& study, bool vtk, const std::string* design,
                          DesignChoice* choice) {
  *choice = DesignChoice();
  if (design && !vtk)
    return "--design chooses the design the VTK files draw: give --vtk too (or \"outputs\": "
           "{\"vtk\": true} in the study)";
  if (!vtk) return "";
  if (!study.design) {
    if (design)
      return "--design " + *design +
             ": the study has no design study (sweep or optimization) to choose from";
    return "";  // a single run draws its analyses as they run
  }
  const DesignStudy& plan = *study.design;
  switch (plan.type) {
    case DesignStudy::Type::kSweep: {
      const long n = static_cast<long>(sweep_designs(plan).size());
      const std::string range = "0.." + std::to_string(n - 1);
      if (!design)
        return "a sweep has no best design to draw in VTK files: choose its row with --design "
               "INDEX (" +
               range + ", the index column of samples.csv)";
      const long i = whole_number(*design);
      if (i < 0 || i >= n)
        return "--design " + *design + ": the sweep's designs are " + range +
               " (the index column of samples.csv)";
      choice->kind = DesignChoice::Kind::kSweepRow;
      choice->index = i;
      return "";
    }
    case DesignStudy::Type::kOptimize: {
      if (!design) {
        choice->kind = DesignChoice::Kind::kBest;
        return "";
      }
      const OptimizePlan& o = plan.optimize;
      const size_t colon = design->find(':');
      const long start = colon == std::string::npos ? 1 : whole_number(design->substr(0, colon));
      const long evaluation =
          whole_number(colon == std::string::npos ? *design : design->substr(colon + 1));
      if (start < 1 || start > o.starts || evaluation < 1 || evaluation > o.max_evaluations)
        return "--design " + *design +
               ": an optimization's design is EVALUATION (of start 1) or START:EVALUATION, "
               "start 1.." +
               std::to_string(o.starts) + ", evaluation 1.." + std::to_string(o.max_evaluations) +
               " (the columns of history.csv)";
      choice->kind = DesignChoice::Kind::kHistoryRow;
      choice->start = start;
      choice->evaluation = evaluation;
      return "";
    }
    case DesignStudy::Type::kWorkPrecision:
    case DesignStudy::Type::kSensitivity:
      if (design)
        return "--design " + *design +
               ": a work-precision or sensitivity study draws the study's own design; it has no "
               "rows to choose from";
      choice->kind = DesignChoice::Kind::kOwn;
      return "";
  }
  return "";
}

DesignToDraw design_to_draw(const Study& study, const DesignChoice& choice,
                            const fs::path& output) {
  DesignToDraw out;
  out.description = describe(choice);
  // Why the design cannot be drawn.
  const auto refuse = [&out](RunOutcome::Kind kind, const std::string& message) {
    out.outcome.kind = kind;
    out.outcome.message = message;
    return std::move(out);
  };
  const std::vector<DesignVariable> none;
  const std::vector<DesignVariable>& variables = study.design ? study.design->variables : none;
  std::vector<double> x;
  nlohmann::json& design = out.record;
  design["study_type"] = study.design->type == DesignStudy::Type::kSweep      ? "sweep"
                         : study.design->type == DesignStudy::Type::kOptimize ? "optimize"
                         : study.design->type == DesignStudy::Type::kWorkPrecision
                             ? "work_precision"
                             : "sensitivity";
  switch (choice.kind) {
    case DesignChoice::Kind::kSweepRow:
      x = sweep_designs(*study.design)[choice.index];
      design["which"] = "row";
      design["index"] = choice.index;
      break;
    case DesignChoice::Kind::kBest: {
      const fs::path file = output / "best.json";
      const nlohmann::json best = nlohmann::json::parse(read_text(file), nullptr, false);
      if (best.is_discarded() || !best.contains("variables"))
        return refuse(RunOutcome::Kind::kFailed,
                      "no VTK files: " + file.string() + " cannot be read");
      for (const DesignVariable& v : variables) x.push_back(best["variables"].value(v.name, 0.0));
      design["which"] = "best";
      design["start"] = best.value("start", 0);
      design["evaluation"] = best.value("evaluation", 0);
      break;
    }
    case DesignChoice::Kind::kHistoryRow: {
      const fs::path file = output / "history.csv";
      std::istringstream lines(read_text(file));
      std::string line;
      std::getline(lines, line);
      const CsvRow header = parse_csv_line(line);
      std::vector<size_t> columns;
      for (const DesignVariable& v : variables)
        for (size_t c = 0; c < header.size(); ++c)
          if (header[c] == v.name) columns.push_back(c);
      long last = 0;
      while (x.empty() && std::getline(lines, line)) {
        const CsvRow row = parse_csv_line(line);
        if (row.size() < 2 + variables.size() || columns.size() != variables.size()) continue;
        if (whole_number(row[0]) != choice.start) continue;
        const long e = whole_number(row[1]);
        last = std::max(last, e);
        if (e != choice.evaluation) continue;
        for (size_t c : columns) x.push_back(std::strtod(row[c].c_str(), nullptr));
      }
      if (x.empty())
        return refuse(RunOutcome::Kind::kBadInput,
                      "--design " + std::to_string(choice.start) + ":" +
                          std::to_string(choice.evaluation) + ": " + file.string() +
                          " has no such row (start " + std::to_string(choice.start) + " holds " +
                          (last > 0 ? "evaluations 1.." + std::to_string(last) : "no rows") + ")");
      design["which"] = "row";
      design["start"] = choice.start;
      design["evaluation"] = choice.evaluation;
      break;
    }
    case DesignChoice::Kind::kOwn:
    case DesignChoice::Kind::kNone:
      design["which"] = "own";
      break;
  }

  // The study document with the design's values and no design study: what `beamrail run`
  // of best_scene.json would run.
  Json document = study.document;
  document.erase("study");
  if (!x.empty()) {
    nlohmann::json values = nlohmann::json::object();
    for (size_t i = 0; i < variables.size(); ++i) {
      const DesignVariable& v = variables[i];
      for (size_t k = 0; k < v.pointers.size(); ++k)
        document[Json::json_pointer(v.pointers[k])] = v.factors[k] * x[i] + v.offsets[k];
      values[v.name] = x[i];
    }
    design["variables"] = values;
  }
  Diagnostics diag;
  out.study = load_study(document, study.file, study.directory, diag, &study.model.segment_choices);
  if (!out.study) {
    std::string problems = diag.format();
    if (!problems.empty() && problems.back() == '\n') problems.pop_back();
    return refuse(RunOutcome::Kind::kFailed,
                  "no VTK files: " + describe(choice) + " is invalid:\n" + problems);
  }
  return out;
}

}  // namespace beamrail
