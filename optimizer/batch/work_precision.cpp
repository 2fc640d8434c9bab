#include "optimizer/batch/work_precision.hpp"

#include <cmath>
#include <iostream>
#include <limits>

#include "core/analysis/stop_request.hpp"
#include "optimizer/cli/interruption.hpp"
#include "optimizer/output/summary.hpp"
#include "optimizer/output/tables.hpp"
#include "optimizer/output/version.hpp"
#include "optimizer/run/trajectory.hpp"

namespace beamrail {
namespace {

struct RunRecord {
  TransientResult result;
  Trajectory trajectory;
};

RunRecord run(const Model& model, TransientOptions options) {
  RunRecord r;
  r.trajectory = trajectory_of(model);
  Data data(model);
  r.result = run_transient(model, options, data, [&r](const TransientSample& s, const Data& d) {
    r.trajectory.record(s, d);
  });
  return r;
}

}  // namespace

int run_work_precision(const Study& study, const RunSettings& settings) {
  const WorkPrecisionPlan& plan = study.design->work_precision;
  const AnalysisSpec& analysis =
      study.analyses[find_analysis(study, AnalysisSpec::Type::kTransient)];
  TransientOptions base = analysis.transient;
  base.max_seconds = 0.0;
  SparseStructureCache structures;  // every run integrates the same model
  base.structure_cache = &structures;

  TransientOptions reference_options = base;
  reference_options.integrator = plan.reference;
  nlohmann::json summary;
  summary["study"] = study.name;
  summary["file"] = study.file;
  summary["beamrail_version"] = kVersion;
  summary["type"] = "work_precision";
  summary["warnings"] = study.input_warnings;
  // The summary of a run that ends early (status, message); false when it cannot be written.
  const auto write_summary = [&](const std::string& status, const std::string& message) {
    summary["status"] = status;
    summary["message"] = message;
    summary["model"] = model_summary(study.model);
    std::string error;
    if (write_file_atomically(settings.output / "summary.json", summary.dump(2) + "\n", &error))
      return true;
    std::cerr << "beamrail: " << error << "\n";
    return false;
  };

  const RunRecord reference = run(study.model, reference_options);
  if (reference.result.interrupted) {
    const int signal = stop_requested();
    write_summary("interrupted", "interrupted by " + signal_name(signal) + " in the reference run");
    std::cerr << "beamrail: " << study.name << " interrupted by " << signal_name(signal)
              << " in the reference run; nothing to keep\n";
    return interrupted_exit_status(signal);
  }
  if (!reference.result.ok) {
    write_summary("failed", "the reference run failed: " + reference.result.message);
    std::cerr << "beamrail: the reference run failed: " << reference.result.message << "\n";
    return 1;
  }

  CsvWriter table;
  std::string error;
  if (!table.open(settings.output / "work_precision.csv",
                  {"method", "rtol", "atol", "error", "wall_s", "steps", "rhs_evals", "jac_evals",
                   "linear_solver", "status"},
                  &error, true)) {
    write_summary("failed", error);
    std::cerr << "beamrail: " << error << "\n";
    return 1;
  }
  nlohmann::json best = nullptr;
  double best_wall = std::numeric_limits<double>::infinity();
  long runs = 0, failed = 0;
  const long planned = static_cast<long>(plan.methods.size() * plan.rtols.size());
  bool interrupted = false;
  for (const WorkPrecisionPlan::Method& method : plan.methods)
    for (double rtol : plan.rtols) {
      if (stop_requested() || !table.good()) break;
      TransientOptions options = base;
      options.integrator = method.integrator;
      options.integrator.rtol = rtol;
      options.integrator.atol = rtol * plan.atol_scale;
      options.max_seconds = plan.max_seconds;
      const RunRecord r = run(study.model, options);
      if (r.result.interrupted) {
        interrupted = true;  // not a measurement: no row
        break;
      }
      const double e = r.result.ok ? trajectory_error(r.trajectory, reference.trajectory)
                                   : std::numeric_limits<double>::quiet_NaN();
      const std::string status = r.result.ok ? "ok" : r.result.timed_out ? "timeout" : "failed";
      const SolverStats& s = r.result.stats;
      table.row({method.label, format_number(rtol), format_number(options.integrator.atol),
                 format_number(e), format_number(s.wall_seconds), std::to_string(s.steps),
                 std::to_string(s.rhs_evaluations), std::to_string(s.jacobian_evaluations),
                 r.result.linear_solver, status});
      if (!table.flush()) break;
      ++runs;
      failed += !r.result.ok;
      if (r.result.ok && e <= plan.target_error && s.wall_seconds < best_wall) {
        best_wall = s.wall_seconds;
        best = {{"method", method.label},          {"rtol", rtol},
                {"atol", options.integrator.atol}, {"error", e},
                {"wall_seconds", s.wall_seconds},  {"steps", s.steps}};
      }
      if (!settings.quiet)
        std::cerr << method.label << " rtol " << format_number(rtol) << ": error "
                  << format_number(e) << ", " << s.wall_seconds << " s (" << status << ")\n";
    }

  const int signal = stop_requested();
  interrupted = interrupted || (signal != 0 && runs < planned);
  const bool written = table.commit(&error);
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
  if (!written) {
    write_summary("failed", error);
    std::cerr << "beamrail: " << error << "\n";
    return 1;
  }
  if (interrupted) {
    if (!write_summary("interrupted", "interrupted by " + signal_name(signal) + " after " +
                                          std::to_string(runs) + " of " + std::to_string(planned) +
                                          " runs"))
      return 1;
    std::cerr << "beamrail: " << study.name << " interrupted by " << signal_name(signal) << ": "
              << runs << " of " << planned << " runs are in "
              << (settings.output / "work_precision.csv").string()
              << "; a work-precision study does not resume: run it again to measure them all\n";
    return interrupted_exit_status(signal);
  }
  if (!write_summary("ok", "")) return 1;
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
