#include "optimizer/work_precision.hpp"

#include <cmath>
#include <iostream>
#include <limits>

#include "optimizer/summary.hpp"
#include "optimizer/tables.hpp"
#include "optimizer/trajectory.hpp"
#include "optimizer/version.hpp"

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
  const RunRecord reference = run(study.model, reference_options);
  if (!reference.result.ok) {
    std::cerr << "beamrail: the reference run failed: " << reference.result.message << "\n";
    return 1;
  }

  CsvWriter table;
  std::string error;
  if (!table.open(settings.output / "work_precision.csv",
                  {"method", "rtol", "atol", "error", "wall_s", "steps", "rhs_evals", "jac_evals",
                   "linear_solver", "status"},
                  &error)) {
    std::cerr << "beamrail: " << error << "\n";
    return 1;
  }
  nlohmann::json best = nullptr;
  double best_wall = std::numeric_limits<double>::infinity();
  long runs = 0, failed = 0;
  for (const WorkPrecisionPlan::Method& method : plan.methods)
    for (double rtol : plan.rtols) {
      TransientOptions options = base;
      options.integrator = method.integrator;
      options.integrator.rtol = rtol;
      options.integrator.atol = rtol * plan.atol_scale;
      options.max_seconds = plan.max_seconds;
      const RunRecord r = run(study.model, options);
      const double e = r.result.ok ? trajectory_error(r.trajectory, reference.trajectory)
                                   : std::numeric_limits<double>::quiet_NaN();
      const std::string status = r.result.ok ? "ok" : r.result.timed_out ? "timeout" : "failed";
      const SolverStats& s = r.result.stats;
      table.row({method.label, format_number(rtol), format_number(options.integrator.atol),
                 format_number(e), format_number(s.wall_seconds), std::to_string(s.steps),
                 std::to_string(s.rhs_evaluations), std::to_string(s.jacobian_evaluations),
                 r.result.linear_solver, status});
      table.flush();
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

  nlohmann::json summary;
  summary["study"] = study.name;
  summary["file"] = study.file;
  summary["beamrail_version"] = kVersion;
  summary["type"] = "work_precision";
  summary["status"] = "ok";
  summary["runs"] = runs;
  summary["failed_or_timeout"] = failed;
  summary["target_error"] = plan.target_error;
  summary["fastest_within_target"] = best;
  summary["reference"] = {{"method", plan.reference.method},
                          {"rtol", plan.reference.rtol},
                          {"atol", plan.reference.atol},
                          {"wall_seconds", reference.result.stats.wall_seconds},
                          {"steps", reference.result.stats.steps}};
  summary["error_measure"] =
      "largest distance between body centres over the output times, relative to the largest "
      "distance a body moved in the reference run";
  summary["model"] = model_summary(study.model);
  if (!write_file_atomically(settings.output / "summary.json", summary.dump(2) + "\n", &error)) {
    std::cerr << "beamrail: " << error << "\n";
    return 1;
  }
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
