#include "optimizer/output/work_precision_report.hpp"

#include <iostream>
#include <limits>

#include "core/analysis/stop_request.hpp"
#include "optimizer/cli/interruption.hpp"
#include "optimizer/output/summary.hpp"
#include "optimizer/output/version.hpp"
#include "optimizer/run/status.hpp"

namespace beamrail {

bool WorkPrecisionTable::open(const std::filesystem::path& output, std::string* error) {
  return table_.open(output / "work_precision.csv",
                     {"method", "rtol", "atol", "error", "wall_s", "steps", "rhs_evals",
                      "jac_evals", "linear_solver", "status"},
                     error, true);
}

void WorkPrecisionTable::write(const PrecisionRun& r) {
  table_.row({r.method, format_number(r.rtol), format_number(r.atol), format_number(r.error),
              format_number(r.stats.wall_seconds), std::to_string(r.stats.steps),
              std::to_string(r.stats.rhs_evaluations), std::to_string(r.stats.jacobian_evaluations),
              r.linear_solver, r.status()});
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

// Writes the summary with its status and message; false (printed) when it cannot be written.
bool write_summary(nlohmann::json& s, const Study& study, const RunSettings& settings,
                   const std::string& status, const std::string& message) {
  s["status"] = status;
  s["message"] = message;
  s["model"] = model_summary(study.model);
  std::string error;
  if (write_file_atomically(settings.output / "summary.json", s.dump(2) + "\n", &error))
    return true;
  std::cerr << "beamrail: " << error << "\n";
  return false;
}

}  // namespace

int report_no_runs(const Study& study, const RunSettings& settings,
                   const PrecisionReference& reference, const std::string& table_error) {
  nlohmann::json s = base_summary(study);
  if (reference.result.interrupted) {
    const int signal = stop_requested();
    write_summary(s, study, settings, status_name(Status::kInterrupted),
                  "interrupted by " + signal_name(signal) + " in the reference run");
    std::cerr << "beamrail: " << study.name << " interrupted by " << signal_name(signal)
              << " in the reference run; nothing to keep\n";
    return interrupted_exit_status(signal);
  }
  const std::string message =
      !reference.result.ok ? "the reference run failed: " + reference.result.message : table_error;
  write_summary(s, study, settings, status_name(Status::kFailed), message);
  std::cerr << "beamrail: " << message << "\n";
  return 1;
}

int report_work_precision(const Study& study, const RunSettings& settings,
                          const PrecisionReference& reference, const WorkPrecisionResult& result,
                          const std::string& table_error) {
  const WorkPrecisionPlan& plan = study.design->work_precision;
  nlohmann::json summary = base_summary(study);
  // The fastest run within the target error (the first of equal times, in plan order).
  nlohmann::json best = nullptr;
  double best_wall = std::numeric_limits<double>::infinity();
  long failed = 0;
  for (const PrecisionRun& r : result.runs) {
    failed += !r.ok;
    if (r.ok && r.error <= plan.target_error && r.stats.wall_seconds < best_wall) {
      best_wall = r.stats.wall_seconds;
      best = {{"method", r.method},
              {"rtol", r.rtol},
              {"atol", r.atol},
              {"error", r.error},
              {"wall_seconds", r.stats.wall_seconds},
              {"steps", r.stats.steps}};
    }
  }
  const long runs = static_cast<long>(result.runs.size());
  const int signal = stop_requested();
  const bool interrupted = result.interrupted || (signal != 0 && runs < result.planned);
  summary["runs"] = runs;
  summary["failed_or_timeout"] = failed;
  summary["target_error"] = plan.target_error;
  summary["fastest_within_target"] = best;
  summary["reference"] = {{"method", method_name(plan.reference.method)},
                          {"rtol", plan.reference.rtol},
                          {"atol", plan.reference.atol},
                          {"wall_seconds", reference.result.stats.wall_seconds},
                          {"steps", reference.result.stats.steps}};
  summary["error_measure"] =
      "largest distance between body centres over the output times, relative to the largest "
      "distance a body moved in the reference run";
  summary["ranks"] = result.ranks;
  if (result.ranks > 1) summary["runs_per_rank"] = result.runs_per_rank;
  if (!table_error.empty()) {
    write_summary(summary, study, settings, status_name(Status::kFailed), table_error);
    std::cerr << "beamrail: " << table_error << "\n";
    return 1;
  }
  if (interrupted) {
    if (!write_summary(summary, study, settings, status_name(Status::kInterrupted),
                       "interrupted by " + signal_name(signal) + " after " + std::to_string(runs) +
                           " of " + std::to_string(result.planned) + " runs"))
      return 1;
    std::cerr << "beamrail: " << study.name << " interrupted by " << signal_name(signal) << ": "
              << runs << " of " << result.planned << " runs are in "
              << (settings.output / "work_precision.csv").string()
              << "; a work-precision study does not resume: run it again to measure them all\n";
    return interrupted_exit_status(signal);
  }
  if (!write_summary(summary, study, settings, status_name(Status::kOk), "")) return 1;
  std::cout << study.name << ": " << runs << " runs (" << failed << " failed or timed out)";
  if (!best.is_null())
    std::cout << "; fastest within " << format_number(plan.target_error) << ": "
              << best["method"].get<std::string>() << " at rtol "
              << format_number(best["rtol"].get<double>()) << " in "
              << best["wall_seconds"].get<double>() << " s";
  std::cout << " -> " << settings.output.string() << "\n";
  return 0;
}

}  // namespace beamrail
