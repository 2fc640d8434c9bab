#include "optimizer/cli/batch_commands.hpp"

#include <chrono>
#include <iostream>

#include "optimizer/batch/optimize.hpp"
#include "optimizer/batch/sensitivity_study.hpp"
#include "optimizer/batch/sweep.hpp"
#include "optimizer/batch/work_precision.hpp"
#include "optimizer/cli/interruption.hpp"
#include "optimizer/output/optimization_report.hpp"
#include "optimizer/output/sensitivity_report.hpp"
#include "optimizer/output/summary.hpp"
#include "optimizer/output/sweep_report.hpp"
#include "optimizer/output/vtk_output.hpp"
#include "optimizer/output/work_precision_report.hpp"
#include "optimizer/run/evaluation.hpp"
#include "optimizer/run/number_text.hpp"
#include "optimizer/run/status.hpp"

namespace beamrail {

int exit_status(const RunOutcome& outcome) {
  switch (outcome.kind) {
    case RunOutcome::Kind::kOk:
      return 0;
    case RunOutcome::Kind::kInterrupted:
      return interrupted_exit_status(outcome.signal);
    case RunOutcome::Kind::kBadInput:
      return 2;
    case RunOutcome::Kind::kFailed:
    case RunOutcome::Kind::kWriteError:
      break;
  }
  return 1;
}

namespace {

// The write errors of an outcome, a line each.
void print_errors(const RunOutcome& outcome) {
  for (const std::string& e : outcome.errors) std::cerr << "beamrail: " << e << "\n";
}

// A batch that failed before its first design (its summary written, or not).
int failed_before_designs(const Study& study, const RunOutcome& outcome) {
  print_errors(outcome);
  std::cerr << "beamrail: " << study.name << " failed: " << outcome.message << "\n";
  return exit_status(outcome);
}

// A batch table that could not be opened (error: why): 2 for a resumed table of other columns
// (the study was edited), 1 for a write error; 0 when it opened.
int open_exit_status(BatchTable::Opened opened, const std::string& error) {
  if (opened == BatchTable::Opened::kOk) return 0;
  std::cerr << "beamrail: " << error << "\n";
  return opened == BatchTable::Opened::kOtherColumns ? 2 : 1;
}

}  // namespace

int run_sweep(const Study& study, const RunSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  const DesignEvaluator evaluator(study);
  if (!evaluator.setup_failure().empty())
    return failed_before_designs(
        study, fail_before_designs(study, settings.output, "sweep", evaluator.setup_failure()));
  SweepTable table(study, settings);
  if (const int status = open_exit_status(table.open(), table.error())) return status;
  SweepRun run =
      sweep(study, evaluator, settings, table.resumed(), table.resumed_failed(),
            [&](long i, const Design& x, const DesignOutcome& o) { return table.append(i, x, o); });
  const bool written = table.finalize();
  // The whole run's time, the evaluator's set-up and the table's sorting included.
  run.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const SweepReport report = report_sweep(study, settings, table, run, written);
  const RunOutcome& outcome = report.outcome;
  print_errors(outcome);
  if (outcome.kind == RunOutcome::Kind::kInterrupted)
    std::cerr << "beamrail: " << study.name << " interrupted by " << signal_name(outcome.signal)
              << ": " << report.finished << " of " << run.designs << " designs are in "
              << table.path().string() << "; continue with: " << settings.command << " --resume\n";
  if (outcome.kind == RunOutcome::Kind::kOk)
    std::cout << study.name << ": " << run.designs << " designs (" << report.failed
              << " failed or invalid, " << report.with_warnings << " with warnings) in "
              << run.wall_seconds << " s -> " << settings.output.string() << "\n";
  return exit_status(outcome);
}

int run_optimize(const Study& study, const RunSettings& settings) {
  const OptimizationProblem problem(study);
  const DesignEvaluator evaluator(study);
  if (!evaluator.setup_failure().empty())
    return failed_before_designs(
        study, fail_before_designs(study, settings.output, "optimize", evaluator.setup_failure()));
  OptimizationFiles files(problem, settings);
  if (const int status = open_exit_status(files.open(), files.error())) return status;
  const OptimizationRun run =
      optimize(problem, evaluator, settings, files.resumed(), files.resumed_derivatives(), files);
  const bool written = files.finalize();
  const OptimizationReport report =
      report_optimization(problem, evaluator, settings, run, written ? "" : files.error());
  const RunOutcome& outcome = report.outcome;
  for (const std::string& w : report.warnings) std::cerr << "warning: " << w << "\n";
  print_errors(outcome);
  const size_t designs = run.records.size();
  const std::string history = (settings.output / "history.csv").string();
  switch (outcome.kind) {
    case RunOutcome::Kind::kOk: {
      const OptimizationRecord& best = *report.best;
      const std::vector<DesignVariable>& variables = problem.variables();
      std::cout << study.name << ": best objective " << format_number(best.objective) << " at";
      for (size_t i = 0; i < variables.size(); ++i)
        std::cout << " " << variables[i].name << " = " << format_number(best.x[i]);
      std::cout << " (" << designs << " designs, " << run.wall_seconds << " s) -> "
                << settings.output.string() << "\n";
      break;
    }
    case RunOutcome::Kind::kInterrupted:
      std::cerr << "beamrail: " << study.name << " interrupted by " << signal_name(outcome.signal)
                << ": " << designs << " designs are in " << history
                << "; continue with: " << settings.command << " --resume\n";
      break;
    case RunOutcome::Kind::kFailed:
      if (report.status == RunStatus::kInfeasible)
        std::cerr << "beamrail: " << study.name << ": " << outcome.message << " (" << designs
                  << " designs evaluated); see " << history << "\n";
      else
        std::cerr << "beamrail: " << study.name << " failed: " << outcome.message << "\n("
                  << designs << " designs evaluated are in " << history
                  << "; no best.json is written)\n";
      break;
    case RunOutcome::Kind::kBadInput:
    case RunOutcome::Kind::kWriteError:
      break;
  }
  return exit_status(outcome);
}

int run_work_precision(const Study& study, const RunSettings& settings) {
  const PrecisionReference reference = run_reference(study);
  WorkPrecisionTable table;
  std::string error;
  WorkPrecisionReport report;
  if (!reference.result.ok) {
    report = report_no_runs(study, settings, reference, "");
  } else if (!table.open(settings.output, &error)) {
    report = report_no_runs(study, settings, reference, error);
  } else {
    const WorkPrecisionResult result =
        measure_work_precision(study, reference, [&](const PrecisionRun& r) {
          if (!settings.quiet)
            std::cerr << r.method << " rtol " << format_number(r.rtol) << ": error "
                      << format_number(r.error) << ", rotation error "
                      << format_number(r.rotation_error) << ", " << r.stats.wall_seconds << " s ("
                      << r.status() << ")\n";
          return table.add(r);
        });
    const bool written = table.commit(&error);
    report = report_work_precision(study, settings, reference, result, written ? "" : error);
  }
  const RunOutcome& outcome = report.outcome;
  print_errors(outcome);
  switch (outcome.kind) {
    case RunOutcome::Kind::kOk:
      std::cout << study.name << ": " << report.runs << " runs (" << report.failed
                << " failed or timed out)";
      if (!report.fastest_method.empty())
        std::cout << "; fastest within " << format_number(study.design->work_precision.target_error)
                  << ": " << report.fastest_method << " at rtol "
                  << format_number(report.fastest_rtol) << " in " << report.fastest_seconds << " s";
      std::cout << " -> " << settings.output.string() << "\n";
      break;
    case RunOutcome::Kind::kInterrupted:
      if (report.in_reference)
        std::cerr << "beamrail: " << study.name << " interrupted by " << signal_name(outcome.signal)
                  << " in the reference run; nothing to keep\n";
      else
        std::cerr << "beamrail: " << study.name << " interrupted by " << signal_name(outcome.signal)
                  << ": " << report.runs << " of " << report.planned << " runs are in "
                  << (settings.output / "work_precision.csv").string()
                  << "; a work-precision study does not resume: run it again to measure them "
                     "all\n";
      break;
    case RunOutcome::Kind::kFailed:
      std::cerr << "beamrail: " << outcome.message << "\n";
      break;
    case RunOutcome::Kind::kBadInput:
    case RunOutcome::Kind::kWriteError:
      break;
  }
  return exit_status(outcome);
}

int run_sensitivity(const Study& study, const RunSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  const DesignEvaluator evaluator(study);
  if (!evaluator.setup_failure().empty())
    return failed_before_designs(study, fail_before_designs(study, settings.output, "sensitivity",
                                                            evaluator.setup_failure()));
  const SensitivityResult result = compute_sensitivities(study, evaluator, settings);
  const SensitivityReport report = report_sensitivity(study, settings, result, start);
  const RunOutcome& outcome = report.outcome;
  print_errors(outcome);
  if (outcome.kind == RunOutcome::Kind::kWriteError) return exit_status(outcome);
  for (const std::string& w : report.warnings) std::cerr << "warning: " << w << "\n";
  if (outcome.kind != RunOutcome::Kind::kOk) {
    std::cerr << "beamrail: " << study.name << " " << run_status_name(report.status) << ": "
              << outcome.message << "\n";
    // A sensitivity study stopped by a signal has always exited 1, not 128 + the signal.
    return 1;
  }
  const DesignStudy& plan = *study.design;
  std::cout << study.name << ": derivatives of " << study.responses.size()
            << " responses with respect to " << plan.variables.size() << " variables in "
            << report.wall_seconds << " s";
  if (plan.sensitivity.check)
    std::cout << " (largest relative difference from central differences "
              << format_number(report.largest_relative_difference) << ")";
  std::cout << " -> " << settings.output.string() << "\n";
  return 0;
}

int draw_design(const Study& study, const DesignChoice& choice, const std::filesystem::path& output,
                bool quiet) {
  if (choice.kind == DesignChoice::Kind::kNone) return 0;
  DesignToDraw drawn = design_to_draw(study, choice, output);
  if (drawn.outcome.kind != RunOutcome::Kind::kOk) {
    std::cerr << "beamrail: " << drawn.outcome.message << "\n";
    return exit_status(drawn.outcome);
  }
  VtkOutput vtk(output / "vtk");
  EvaluationOptions options;
  options.vtk = &vtk;
  const Evaluation ev = evaluate(*drawn.study, drawn.study->model, options);
  drawn.record["status"] = status_name(ev.status);
  drawn.record["message"] = ev.message;
  std::string error;
  if (!vtk.finish(drawn.record, &error)) {
    std::cerr << "beamrail: " << error << "\n";
    return 1;
  }
  if (ev.status != Status::kOk) {
    std::cerr << "beamrail: the VTK files of " << drawn.description
              << " are incomplete: " << status_name(ev.status) << ": " << ev.message << "\n";
    return 1;
  }
  if (!quiet)
    std::cerr << "beamrail: VTK files of " << drawn.description << " in "
              << (output / "vtk").string() << " (open a .pvd in ParaView)\n";
  return 0;
}

}  // namespace beamrail
