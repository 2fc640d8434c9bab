#include "optimizer/output/optimization_report.hpp"

#include <nlopt.h>

#include <cmath>
#include <cstdlib>

#include "core/analysis/stop_request.hpp"
#include "optimizer/output/summary.hpp"
#include "optimizer/output/tables.hpp"
#include "optimizer/output/version.hpp"
#include "optimizer/run/status.hpp"
#include "optimizer/study/nlopt_setup.hpp"

namespace beamrail {

CsvRow history_header(const OptimizationProblem& problem) {
  CsvRow header{"start", "evaluation"};
  for (const DesignVariable& v : problem.variables()) header.push_back(v.name);
  for (const ResponseSpec& r : problem.study().responses) header.push_back(r.name);
  for (const char* c : {"objective", "feasible", "status", "warnings", "wall_s", "message"})
    header.push_back(c);
  return header;
}

CsvRow history_row(const OptimizationRecord& r) {
  CsvRow out{std::to_string(r.start), std::to_string(r.evaluation)};
  for (double x : r.x) out.push_back(format_number(x));
  for (double v : r.outcome.responses) out.push_back(format_number(v));
  out.push_back(format_number(r.objective));
  out.push_back(r.feasible ? "1" : "0");
  out.push_back(status_name(r.outcome.status));
  out.push_back(std::to_string(r.outcome.warnings));
  out.push_back(format_number(r.outcome.wall_seconds));
  out.push_back(r.outcome.message);
  return out;
}

BatchTable::Opened OptimizationFiles::open() {
  const std::vector<DesignVariable>& variables = problem_.variables();
  const std::vector<ResponseSpec>& responses = problem_.study().responses;
  // A best design of an earlier run must not stand beside this run's history.
  for (const char* stale : {"best.json", "best_scene.json"}) {
    std::error_code ec;
    std::filesystem::remove(settings_.output / stale, ec);
  }
  std::vector<CsvRow> existing;
  if (const BatchTable::Opened opened =
          history_.open(settings_.output / "history.csv", history_header(problem_),
                        settings_.resume, &existing, &error_);
      opened != BatchTable::Opened::kOk)
    return opened;
  const size_t nv = variables.size(), nr = responses.size();
  for (const CsvRow& r : existing) {
    ResumedRow row;
    row.start = static_cast<int>(std::strtol(r[0].c_str(), nullptr, 10));
    for (size_t i = 0; i < nv; ++i) row.x.push_back(std::strtod(r[2 + i].c_str(), nullptr));
    DesignOutcome& o = row.outcome;
    for (size_t k = 0; k < nr; ++k)
      o.responses.push_back(std::strtod(r[2 + nv + k].c_str(), nullptr));
    o.status = status_from_name(r[2 + nv + nr + 2]).value_or(Status::kFailed);
    o.warnings = static_cast<int>(std::strtol(r[2 + nv + nr + 3].c_str(), nullptr, 10));
    o.wall_seconds = std::strtod(r[2 + nv + nr + 4].c_str(), nullptr);
    o.message = r[2 + nv + nr + 5];
    resumed_.push_back(std::move(row));
  }
  // The derivatives of earlier designs (exact gradients), by design.
  if (!problem_.exact_gradients()) return BatchTable::Opened::kOk;
  CsvRow columns;
  for (const DesignVariable& v : variables) columns.push_back(v.name);
  for (const ResponseSpec& r : responses)
    for (const DesignVariable& v : variables) columns.push_back("d " + r.name + " / d " + v.name);
  std::vector<CsvRow> rows;
  if (const BatchTable::Opened opened = derivatives_.open(
          settings_.output / "derivatives.csv", columns, settings_.resume, &rows, &error_);
      opened != BatchTable::Opened::kOk)
    return opened;
  for (const CsvRow& r : rows) {
    Design x;
    for (size_t i = 0; i < nv; ++i) x.push_back(std::strtod(r[i].c_str(), nullptr));
    Eigen::MatrixXd jacobian(nr, nv);
    for (size_t k = 0; k < nr; ++k)
      for (size_t j = 0; j < nv; ++j)
        jacobian(k, j) = std::strtod(r[nv + k * nv + j].c_str(), nullptr);
    derivatives_read_.emplace_back(std::move(x), std::move(jacobian));
  }
  return BatchTable::Opened::kOk;
}

void OptimizationFiles::record(const OptimizationRecord& r) {
  if (!history_.append(history_row(r))) failed_ = true;
}

void OptimizationFiles::derivatives(const Design& x, const Eigen::MatrixXd& jacobian) {
  CsvRow row;
  for (double v : x) row.push_back(format_number(v));
  for (Eigen::Index k = 0; k < jacobian.rows(); ++k)
    for (Eigen::Index j = 0; j < jacobian.cols(); ++j) row.push_back(format_number(jacobian(k, j)));
  if (!derivatives_.append(row)) failed_ = true;
}

bool OptimizationFiles::finalize() {
  if (!history_.finalize({0, 1}, &error_)) return false;
  if (!problem_.exact_gradients()) return true;
  std::vector<int> keys;
  for (size_t i = 0; i < problem_.variables().size(); ++i) keys.push_back(static_cast<int>(i));
  return derivatives_.finalize(keys, &error_);
}

namespace {

nlohmann::json constraint_report(const OptimizationProblem& problem, const DesignOutcome& o) {
  const OptimizePlan& plan_ = problem.plan();
  const Study& study_ = problem.study();
  nlohmann::json list = nlohmann::json::array();
  const double tolerance = problem.active_tolerance();
  for (const Constraint& c : plan_.constraints) {
    const double value = o.responses[c.response];
    double margin = 0.0;  // positive: satisfied with room, in the response's units
    const char* type = "";
    switch (c.kind) {
      case Constraint::Kind::kAtLeast:
        margin = value - c.bound, type = ">=";
        break;
      case Constraint::Kind::kAtMost:
        margin = c.bound - value, type = "<=";
        break;
      case Constraint::Kind::kAbsAtMost:
        margin = c.bound - std::abs(value), type = "abs<=";
        break;
    }
    // The negative of constraint_of(): satisfied is what feasible() requires of the constraint.
    const double relative = c.bound != 0.0 ? margin / std::abs(c.bound) : margin;
    const bool finite = std::isfinite(relative);
    list.push_back({{"response", study_.responses[c.response].name},
                    {"type", type},
                    {"bound", c.bound},
                    {"value", json_number(value)},
                    {"margin", json_number(margin)},
                    {"relative_margin", json_number(relative)},
                    {"active", finite && std::abs(relative) <= tolerance},
                    {"satisfied", finite && relative >= -kFeasibility}});
  }
  return list;
}

// Why a start stopped, in words.
std::string stop_reason(const OptimizePlan& plan_, const StartResult& st) {
  const std::string budget = std::to_string(plan_.max_evaluations);
  switch (st.result) {
    case NLOPT_SUCCESS:
      return "the algorithm's own convergence test was met";
    case NLOPT_STOPVAL_REACHED:
      return "the objective reached NLopt's stopval";
    case NLOPT_FTOL_REACHED:
      return "a step changed the objective by less than ftol_rel (" +
             format_number(plan_.ftol_rel) + ") of its value";
    case NLOPT_XTOL_REACHED:
      return "a step changed every variable, scaled to [0, 1] by its bounds, by less than "
             "xtol_rel (" +
             format_number(plan_.xtol_rel) + ") of its value";
    case NLOPT_MAXEVAL_REACHED:
      if (st.budget_spent)
        return "the design budget is spent: the start had evaluated " + std::to_string(st.designs) +
               " of its " + budget + " designs (max_evaluations) and NLopt's next call needed " +
               std::to_string(st.budget_needed) + " more; beamrail stopped NLopt without it";
      return "NLopt reached its own limit of max_evaluations (" + budget + ") calls" +
             (needs_gradient(plan_.algorithm)
                  ? std::string(" (calls at designs the start had evaluated cost no designs)")
                  : std::string(" (without gradients a call is one design at most)"));
    case NLOPT_MAXTIME_REACHED:
      return "the start ran for max_seconds (" + format_number(plan_.max_seconds) + " s)";
    case NLOPT_ROUNDOFF_LIMITED:
      return "roundoff errors limited NLopt's progress: the best design may not be an optimum";
    case NLOPT_FORCED_STOP:
      return st.stopped ? "beamrail stopped NLopt: a stop was requested (SIGINT, SIGTERM) or "
                          "history.csv could not be written"
                        : "NLopt was forced to stop, not by beamrail";
    case NLOPT_FAILURE:
      return "NLopt failed" + (st.message.empty() ? std::string() : ": " + st.message);
    case NLOPT_INVALID_ARGS:
      return "NLopt refused its arguments" +
             (st.message.empty() ? std::string() : ": " + st.message);
    case NLOPT_OUT_OF_MEMORY:
      return "NLopt ran out of memory";
    default:
      return "NLopt returned " + std::to_string(static_cast<int>(st.result));
  }
}

// What a start's NLopt result means for the study: "" (a normal stop), or a warning, or an error.
struct StopMeaning {
  std::string warning, error;
};

StopMeaning meaning_of(int index, nlopt_result result, bool stopped_by_us,
                       const std::string& nlopt_message) {
  StopMeaning m;
  if (result > 0 || (result == NLOPT_FORCED_STOP && stopped_by_us)) return m;
  const std::string start = "start " + std::to_string(index) + ": ";
  const std::string name = nlopt_result_to_string(result);
  if (result == NLOPT_ROUNDOFF_LIMITED) {
    m.warning = start +
                "NLopt stopped early because roundoff errors limited its progress "
                "(ROUNDOFF_LIMITED): the designs it evaluated are in the history, but the best of "
                "them may not be an optimum";
    return m;
  }
  m.error = start + "NLopt failed (" + name + ")" +
            (nlopt_message.empty() ? std::string() : ": " + nlopt_message);
  return m;
}

}  // namespace

OptimizationReport report_optimization(const OptimizationProblem& problem,
                                       const DesignEvaluator& evaluator,
                                       const RunSettings& settings_, const OptimizationRun& run,
                                       const std::string& history_error) {
  const Study& study_ = problem.study();
  const OptimizePlan& plan_ = problem.plan();
  const std::vector<DesignVariable>& variables_ = problem.variables();
  const std::vector<OptimizationRecord>& records_ = run.records;
  const std::vector<StartResult>& starts = run.starts;
  const EvaluationCost& cost = run.cost;
  const double wall = run.wall_seconds;
  // The best feasible design; ties go to the earliest (start, evaluation): records_ is sorted.
  const OptimizationRecord* best = nullptr;
  for (const OptimizationRecord& r : records_)
    if (r.feasible && (!best || r.objective < best->objective)) best = &r;
  const int signal = stop_requested();
  std::vector<std::string> warnings = study_.input_warnings, errors;
  bool stopped = false;
  for (const StartResult& st : starts) {
    const StopMeaning m = meaning_of(st.index, st.result, st.stopped, st.message);
    if (!m.warning.empty()) warnings.push_back(m.warning);
    if (!m.error.empty()) errors.push_back(m.error);
    stopped = stopped || st.stopped;
  }
  if (cost.gradient_fallbacks > 0)
    warnings.push_back(std::to_string(cost.gradient_fallbacks) +
                       " design(s) had no exact derivatives, and their gradients came from "
                       "central differences: " +
                       cost.fallback_reason);
  for (const std::string& w : cost.sensitivity_warnings) warnings.push_back("derivatives: " + w);
  const bool interrupted = signal != 0 && stopped;
  RunStatus status = RunStatus::kOk;
  std::string message;
  if (!history_error.empty()) {
    status = RunStatus::kFailed, message = history_error;
  } else if (!errors.empty()) {
    status = RunStatus::kFailed;
    for (const std::string& e : errors) message += (message.empty() ? "" : "; ") + e;
  } else if (interrupted) {
    status = RunStatus::kInterrupted;
    message = "interrupted by " + signal_name(signal) + " after " +
              std::to_string(records_.size()) + " designs";
  } else if (best) {
    status = RunStatus::kOk;
  } else {
    status = RunStatus::kInfeasible;
    message = "no evaluated design satisfies every constraint";
    long warned = 0;
    for (const OptimizationRecord& r : records_)
      warned += r.outcome.status == Status::kOk && r.outcome.warnings > 0;
    if (warned > 0 && plan_.warned_designs == OptimizePlan::WarnedDesigns::kInfeasible)
      message += " (" + std::to_string(warned) +
                 " designs with warnings count as infeasible; their warnings are in the message "
                 "column of history.csv; \"warned_designs\": \"accept\" accepts them)";
  }

  nlohmann::json s;
  s["study"] = study_.name;
  s["file"] = study_.file;
  s["beamrail_version"] = kVersion;
  s["type"] = "optimize";
  s["algorithm"] = plan_.algorithm;
  s["optimizer"] = NloptSetup(plan_, variables_).description();
  s["status"] = run_status_name(status);
  s["message"] = message;
  s["warnings"] = warnings;
  s["max_evaluations"] = plan_.max_evaluations;
  s["active_tolerance"] = problem.active_tolerance();
  nlohmann::json per_start = nlohmann::json::array();
  for (const StartResult& st : starts) {
    // The start's best feasible design; ties go to its earliest evaluation (records_ is sorted).
    const OptimizationRecord* own = nullptr;
    for (const OptimizationRecord& r : records_)
      if (r.start == st.index && r.feasible && (!own || r.objective < own->objective)) own = &r;
    nlohmann::json start_best = nullptr;
    if (own) {
      nlohmann::json vars = nlohmann::json::object();
      for (size_t i = 0; i < variables_.size(); ++i) vars[variables_[i].name] = own->x[i];
      start_best = {{"evaluation", own->evaluation},
                    {"objective", json_number(own->objective)},
                    {"variables", vars}};
    }
    per_start.push_back({{"start", st.index},
                         {"nlopt_result", nlopt_result_to_string(st.result)},
                         {"stop_reason", stop_reason(plan_, st)},
                         {"nlopt_evaluations", st.nlopt_evaluations},
                         {"designs", st.designs},
                         {"best", start_best}});
  }
  s["starts"] = per_start;
  // The problem NLopt sees.
  nlohmann::json scaling;
  nlohmann::json vars = nlohmann::json::array(), cons = nlohmann::json::array();
  for (const DesignVariable& v : variables_)
    vars.push_back({{"name", v.name}, {"lower", v.lower}, {"upper", v.upper}});
  for (size_t j = 0; j < plan_.constraints.size(); ++j)
    cons.push_back({{"response", study_.responses[plan_.constraints[j].response].name},
                    {"scale", run.constraint_scales.at(j)}});
  nlohmann::json objective_scales = nlohmann::json::array();
  for (const StartResult& st : starts) objective_scales.push_back(st.objective_scale);
  scaling["variables"] = vars;
  scaling["variables_seen_as"] = "(x - lower) / (upper - lower), in [0, 1]";
  scaling["objective_scale"] = objective_scales;
  scaling["objective_seen_as"] = "objective / objective_scale (per start)";
  scaling["constraints"] = cons;
  scaling["constraints_seen_as"] =
      "violation in the response's units / scale, <= 0 when met (value - bound for <=, bound - "
      "value for >=, |value| - bound for abs<=)";
  s["scaling"] = scaling;
  if (needs_gradient(plan_.algorithm)) {
    nlohmann::json g;
    g["method"] = problem.exact_gradients() ? "exact" : "fd";
    if (problem.exact_gradients()) {
      g["designs_with_exact_derivatives"] = cost.exact_gradients;
      g["designs_by_differences"] = cost.gradient_fallbacks;
      if (cost.gradient_fallbacks > 0) g["why_differences"] = cost.fallback_reason;
    } else {
      g["step"] = plan_.gradient_step;
    }
    s["gradient"] = g;
  }
  s["designs_simulated"] = cost.simulated;
  s["designs_failed"] = cost.failures;
  long warned = 0;
  for (const OptimizationRecord& r : records_) warned += r.outcome.warnings > 0;
  s["designs_with_warnings"] = warned;
  s["warned_designs"] = warned_designs_name(plan_.warned_designs);
  s["designs_in_history"] = records_.size();
  s["ranks"] = run.ranks;
  s["threads"] = run.threads;
  if (!run.starts_per_rank.empty()) s["starts_per_rank"] = run.starts_per_rank;
  if (!run.designs_per_rank.empty()) {
    s["designs_per_rank"] = run.designs_per_rank;
    s["scheduler_seconds"] = run.scheduler_seconds;
  }
  s["wall_seconds"] = wall;
  s["evaluations_per_second"] = wall > 0 ? static_cast<double>(cost.simulated) / wall : 0.0;
  s["model"] = model_summary(study_.model);
  std::string error;
  bool ok = true;
  if (best) {
    nlohmann::json b;
    b["objective"] = json_number(best->objective);
    b["start"] = best->start;
    b["evaluation"] = best->evaluation;
    nlohmann::json vars = nlohmann::json::object(), resp = nlohmann::json::object();
    for (size_t i = 0; i < variables_.size(); ++i) vars[variables_[i].name] = best->x[i];
    for (size_t k = 0; k < study_.responses.size(); ++k)
      resp[study_.responses[k].name] = json_number(best->outcome.responses[k]);
    b["variables"] = vars;
    b["responses"] = resp;
    b["constraints"] = constraint_report(problem, best->outcome);
    b["active_tolerance"] = problem.active_tolerance();
    if (status == RunStatus::kOk) {
      s["best"] = b;
      s["responses"] = resp;
      Json scene = evaluator.document(best->x);
      // Every design kept the study scene's "auto" segment counts: so does its re-run.
      const std::string counts = write_segment_counts(scene, study_.model.segment_choices);
      scene["name"] = study_.name + "_best";
      scene["description"] = "The best design found by " + plan_.algorithm + " for study \"" +
                             study_.name + "\" (start " + std::to_string(best->start) +
                             ", evaluation " + std::to_string(best->evaluation) + ")." +
                             (counts.empty() ? ""
                                             : " Its segments are the counts \"auto\" chose for "
                                               "the study's scene, which every design kept: " +
                                                   counts + ".");
      ok =
          write_file_atomically(settings_.output / "best.json", b.dump(2) + "\n", &error) &&
          write_file_atomically(settings_.output / "best_scene.json", scene.dump(2) + "\n", &error);
    } else {
      // An unfinished or failed optimization names no best design (no best.json): the best
      // feasible design it evaluated is given for information.
      s["best_evaluated"] = b;
    }
  }
  ok = ok && write_file_atomically(settings_.output / "summary.json", s.dump(2) + "\n", &error);
  OptimizationReport report;
  report.status = status;
  report.warnings.assign(warnings.begin() + static_cast<long>(study_.input_warnings.size()),
                         warnings.end());
  if (best) report.best = *best;
  RunOutcome& outcome = report.outcome;
  outcome.message = message;
  if (!ok) {
    outcome.kind = RunOutcome::Kind::kWriteError;
    outcome.errors.push_back(error);
  } else if (status == RunStatus::kInterrupted) {
    outcome.kind = RunOutcome::Kind::kInterrupted;
    outcome.signal = signal;
  } else if (status != RunStatus::kOk) {
    outcome.kind = RunOutcome::Kind::kFailed;  // failed, or no design is feasible
  }
  return report;
}

}  // namespace beamrail
