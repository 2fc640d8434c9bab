#include "optimizer/batch/sensitivity_study.hpp"

#include <omp.h>

#include <chrono>
#include <cmath>
#include <iostream>

#include "optimizer/output/summary.hpp"
#include "optimizer/output/tables.hpp"
#include "optimizer/output/version.hpp"
#include "optimizer/run/designs.hpp"

namespace beamrail {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

int run_sensitivity(const Study& study, const RunSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  const DesignStudy& plan = *study.design;
  const DesignEvaluator evaluator(study);
  if (!evaluator.setup_failure().empty())
    return fail_before_designs(study, settings.output, "sensitivity", evaluator.setup_failure());
  std::vector<double> x;
  for (const DesignVariable& v : plan.variables) x.push_back(v.value);
  // The variables' derivatives are computed in parallel.
  const int threads = batch_threads(settings, static_cast<long>(x.size()));
  omp_set_num_threads(threads);

  ResponseSensitivities s;
  const DesignOutcome design = evaluator.evaluate(x, &s);
  const double design_seconds = seconds_since(start);

  // The check: each variable's central difference of the responses, every design evaluated.
  const size_t nr = study.responses.size(), nv = x.size();
  std::vector<std::vector<double>> fd(nr, std::vector<double>(nv, NAN));
  std::vector<double> steps(nv, 0.0);
  std::string check_failure;
  const auto check_start = std::chrono::steady_clock::now();
  if (plan.sensitivity.check && design.status == Status::kOk) {
    for (size_t j = 0; j < nv; ++j) {
      steps[j] = plan.sensitivity.check_step * (x[j] != 0.0 ? std::abs(x[j]) : 1.0);
      std::vector<double> up = x, down = x;
      up[j] += steps[j];
      down[j] -= steps[j];
      const DesignOutcome u = evaluator.evaluate(up), d = evaluator.evaluate(down);
      if (u.status != Status::kOk || d.status != Status::kOk) {
        check_failure = "the check's design along \"" + plan.variables[j].name +
                        "\" did not evaluate: " + (u.status != Status::kOk ? u.message : d.message);
        continue;
      }
      for (size_t k = 0; k < nr; ++k)
        fd[k][j] = (u.responses[k] - d.responses[k]) / (2.0 * steps[j]);
    }
  }
  const double check_seconds = seconds_since(check_start);

  std::vector<std::string> header{"response", "variable", "value", "derivative"};
  if (plan.sensitivity.check)
    for (const char* c : {"central_difference", "relative_difference"}) header.push_back(c);
  CsvWriter table;
  std::string error;
  double worst = 0.0;
  bool written = table.open(settings.output / "sensitivities.csv", header, &error, true);
  if (written) {
    for (size_t k = 0; k < nr; ++k)
      for (size_t j = 0; j < nv; ++j) {
        const double d = s.ok ? s.jacobian(k, j) : NAN;
        std::vector<std::string> row{study.responses[k].name, plan.variables[j].name,
                                     format_number(design.responses[k]), format_number(d)};
        if (plan.sensitivity.check) {
          const double scale = std::max(std::abs(d), std::abs(fd[k][j]));
          const double rel = scale > 0.0 ? std::abs(d - fd[k][j]) / scale : 0.0;
          if (std::isfinite(rel)) worst = std::max(worst, rel);
          row.push_back(format_number(fd[k][j]));
          row.push_back(format_number(rel));
        }
        table.row(row);
      }
    written = table.commit(&error);
  }

  std::string status = "ok", message;
  if (design.status != Status::kOk) {
    status = design.status == Status::kInterrupted ? "interrupted" : "failed";
    message = "the study's design did not evaluate: " + design.message;
  } else if (!s.ok) {
    status = "failed";
    message = s.message;
  } else if (!check_failure.empty()) {
    status = "failed";
    message = check_failure;
  } else if (!written) {
    status = "failed";
    message = error;
  }
  nlohmann::json summary;
  summary["study"] = study.name;
  summary["file"] = study.file;
  summary["beamrail_version"] = kVersion;
  summary["type"] = "sensitivity";
  summary["status"] = status;
  summary["message"] = message;
  std::vector<std::string> warnings = study.input_warnings;
  if (design.warnings > 0) warnings.push_back(design.message);
  warnings.insert(warnings.end(), s.warnings.begin(), s.warnings.end());
  summary["warnings"] = warnings;
  nlohmann::json variables = nlohmann::json::object(), responses = nlohmann::json::object();
  for (size_t j = 0; j < nv; ++j) variables[plan.variables[j].name] = x[j];
  for (size_t k = 0; k < nr; ++k)
    responses[study.responses[k].name] = json_number(design.responses[k]);
  summary["variables"] = variables;
  summary["responses"] = responses;
  summary["design_seconds"] = design_seconds;
  summary["ranks"] = 1;
  summary["threads"] = threads;
  if (plan.sensitivity.check) {
    summary["check_seconds"] = check_seconds;
    summary["check_step"] = plan.sensitivity.check_step;
    summary["largest_relative_difference"] = worst;
  }
  summary["wall_seconds"] = seconds_since(start);
  summary["model"] = model_summary(study.model);
  std::string summary_error;
  if (!write_file_atomically(settings.output / "summary.json", summary.dump(2) + "\n",
                             &summary_error)) {
    std::cerr << "beamrail: " << summary_error << "\n";
    return 1;
  }
  for (const std::string& w : warnings) std::cerr << "warning: " << w << "\n";
  if (status != "ok") {
    std::cerr << "beamrail: " << study.name << " " << status << ": " << message << "\n";
    return 1;
  }
  std::cout << study.name << ": derivatives of " << nr << " responses with respect to " << nv
            << " variables in " << seconds_since(start) << " s";
  if (plan.sensitivity.check)
    std::cout << " (largest relative difference from central differences " << format_number(worst)
              << ")";
  std::cout << " -> " << settings.output.string() << "\n";
  return 0;
}

}  // namespace beamrail
