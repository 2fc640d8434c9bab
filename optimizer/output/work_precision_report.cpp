#include "optimizer/output/work_precision_report.hpp"

#include <limits>

#include "core/analysis/dense_product.hpp"
#include "core/analysis/stop_request.hpp"
#include "optimizer/output/summary.hpp"
#include "optimizer/output/version.hpp"
#include "optimizer/run/status.hpp"

namespace beamrail {

bool WorkPrecisionTable::open(const std::filesystem::path& output, std::string* error) {
  return table_.open(output / "work_precision.csv",
                     {"method", "rtol", "atol", "error", "rotation_error", "wall_s", "steps",
                      "rhs_evals", "jac_evals", "linear_solver", "status"},
                     error, true);
}

void WorkPrecisionTable::write(const PrecisionRun& r) {
  table_.row({r.method, format_number(r.rtol), format_number(r.atol), format_number(r.error),
              format_number(r.rotation_error), format_number(r.stats.wall_seconds),
              std::to_string(r.stats.steps), std::to_string(r.stats.rhs_evaluations),
              std::to_string(r.stats.jacobian_evaluations), r.linear_solver, r.status()});
}

bool WorkPrecisionTable::add(const PrecisionRun& run) {
  waiting_.emplace(run.index, run);
  for (auto it = waiting_.find(next_); it != waiting_.end(); it = waiting_.find(++next_)) {
    write(it->second);
    waiting_.erase(it);
  }
  return table_.flush();
}

bool WorkPrecisionTable::commit(std::string* error) {
  for (const auto& [index, run] : waiting_) write(run);
  waiting_.clear();
  return table_.commit(error);
}

namespace {

nlohmann::json base_summary(const Study& study) {
  nlohmann::json s;
  s["study"] = study.name;
  s["file"] = study.file;
  s["beamrail_version"] = kVersion;
  s["type"] = "work_precision";
  s["warnings"] = study.input_warnings;
  return s;
}

// Writes the summary with its status and message; false, with the error in outcome.errors, when
// it cannot be written.
bool write_summary(nlohmann::json& s, const Study& study, const RunSettings& settings,
                   RunStatus status, const std::string& message, RunOutcome& outcome) {
  s["status"] = run_status_name(status);
  s["message"] = message;
  s["model"] = model_summary(study.model);
  std::string error;
  if (write_file_atomically(settings.output / "summary.json", s.dump(2) + "\n", &error))
    return true;
  outcome.errors.push_back(error);
  return false;
}

}  // namespace

WorkPrecisionReport report_no_runs(const Study& study, const RunSettings& settings,
                                   const PrecisionReference& reference,
                                   const std::string& table_error) {
  nlohmann::json s = base_summary(study);
  WorkPrecisionReport report;
  RunOutcome& outcome = report.outcome;
  if (reference.result.interrupted) {
    const int signal = stop_requested();
    outcome.kind = RunOutcome::Kind::kInterrupted;
    outcome.signal = signal;
    outcome.message = "interrupted by " + signal_name(signal) + " in the reference run";
    report.in_reference = true;
    write_summary(s, study, settings, RunStatus::kInterrupted, outcome.message, outcome);
    return report;
  }
  const bool failed = !reference.result.ok;
  outcome.message = failed ? "the reference run failed: " + reference.result.message : table_error;
  write_summary(s, study, settings, RunStatus::kFailed, outcome.message, outcome);
  outcome.kind = failed ? RunOutcome::Kind::kFailed : RunOutcome::Kind::kWriteError;
  if (!failed) outcome.errors.push_back(table_error);
  return report;
}

WorkPrecisionReport report_work_precision(const Study& study, const RunSettings& settings,
                                          const PrecisionReference& reference,
                                          const WorkPrecisionResult& result,
                                          const std::string& table_error) {
  const WorkPrecisionPlan& plan = study.design->work_precision;
  nlohmann::json summary = base_summary(study);
  WorkPrecisionReport report;
  // The fastest run within the target error in its centres and its rotations (the first of equal
  // times, in plan order).
  nlohmann::json best = nullptr;
  double best_wall = std::numeric_limits<double>::infinity();
  for (const PrecisionRun& r : result.runs) {
    report.failed += !r.ok;
    if (r.ok && r.larger_error() <= plan.target_error && r.stats.wall_seconds < best_wall) {
      best_wall = r.stats.wall_seconds;
      best = {{"method", r.method},
              {"rtol", r.rtol},
              {"atol", r.atol},
              {"error", r.error},
              {"rotation_error", r.rotation_error},
              {"wall_seconds", r.stats.wall_seconds},
              {"steps", r.stats.steps}};
      report.fastest_method = r.method;
      report.fastest_rtol = r.rtol;
      report.fastest_seconds = r.stats.wall_seconds;
    }
  }
  report.runs = static_cast<long>(result.runs.size());
  report.planned = result.planned;
  const int signal = stop_requested();
  const bool interrupted = result.interrupted || (signal != 0 && report.runs < result.planned);
  summary["runs"] = report.runs;
  summary["failed_or_timeout"] = report.failed;
  summary["target_error"] = plan.target_error;
  summary["fastest_within_target"] = best;
  summary["reference"] = {{"method", method_name(plan.reference.method)},
                          {"rtol", plan.reference.rtol},
                          {"atol", plan.reference.atol},
                          {"wall_seconds", reference.result.stats.wall_seconds},
                          {"steps", reference.result.stats.steps}};
  summary["error_measure"] =
      "largest distance between body centres over the output times, relative to the largest "
      "distance a body moved in the reference run (nan when none moves more than 1e-12 m)";
  summary["rotation_error_measure"] =
      "largest angle between body orientations over the output times, relative to the largest "
      "angle a body turned in the reference run (nan when none turns more than 1e-9 rad); a run "
      "is within the target when both errors that could be measured are";
  summary["ranks"] = result.ranks;
  summary["product_threads"] = largest_product_team();  // the runs' dense products
  if (result.ranks > 1) summary["runs_per_rank"] = result.runs_per_rank;
  RunOutcome& outcome = report.outcome;
  if (!table_error.empty()) {
    write_summary(summary, study, settings, RunStatus::kFailed, table_error, outcome);
    outcome.kind = RunOutcome::Kind::kWriteError;
    outcome.errors.push_back(table_error);
    return report;
  }
  if (interrupted) {
    outcome.message = "interrupted by " + signal_name(signal) + " after " +
                      std::to_string(report.runs) + " of " + std::to_string(result.planned) +
                      " runs";
    if (!write_summary(summary, study, settings, RunStatus::kInterrupted, outcome.message,
                       outcome)) {
      outcome.kind = RunOutcome::Kind::kWriteError;
      return report;
    }
    outcome.kind = RunOutcome::Kind::kInterrupted;
    outcome.signal = signal;
    return report;
  }
  if (!write_summary(summary, study, settings, RunStatus::kOk, "", outcome))
    outcome.kind = RunOutcome::Kind::kWriteError;
  return report;
}

}  // namespace beamrail
