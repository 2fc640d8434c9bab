// Design optimization with NLopt: any algorithm by name, objective (minimize, maximize, or
// least-squares targets), inequality constraints on responses, finite-difference gradients
// evaluated in parallel, several starts from Latin-hypercube points, run by the threads of this
// process or spread over the ranks of an MPI job (one start at a time per rank; with fewer starts
// than ranks and difference gradients, the points of each gradient over the ranks), and a history
// that doubles as a cache so that an interrupted run resumes by replaying its evaluations.
//
// optimize() computes and hands every row to a sink; output/optimization_report.hpp writes the
// tables, best.json and summary.json; cli/batch_commands.hpp joins the two, prints and returns
// the exit status.
#pragma once

#include <utility>
#include <vector>

#include "optimizer/batch/run_settings.hpp"
#include "optimizer/batch/start_runner.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {

// A row of history.csv read back on --resume.
struct ResumedRow {
  int start = 0;
  Design x;
  DesignOutcome outcome;
};

// What an optimization did.
struct OptimizationRun {
  std::vector<StartResult> starts;          // in start order
  std::vector<OptimizationRecord> records;  // the rows of history.csv, by (start, evaluation)
  // NLopt sees constraint j as (violation in the response's units) / constraint_scales[j]
  std::vector<double> constraint_scales;
  EvaluationCost cost;  // of every design evaluated
  int ranks = 1, threads = 1;
  // Under mpirun: the starts each rank ran, or (the ranks evaluating the points of each gradient)
  // the designs each rank evaluated and rank 0's CPU time spent scheduling them.
  std::vector<long> starts_per_rank, designs_per_rank;
  double scheduler_seconds = 0.0;
  double wall_seconds = 0.0;
};

// Runs the optimization of problem.study(): its starts on the threads of this process, or on the
// ranks of the MPI job of this process (rank 0). Designs of earlier runs (`resumed` rows of
// history.csv and `derivatives`) are replayed, not evaluated. Every row and derivative goes to
// `out` as it is made; the run stops early (as on a stop request) once `out` is no longer good().
OptimizationRun optimize(const OptimizationProblem& problem, const DesignEvaluator& evaluator,
                         const RunSettings& settings, const std::vector<ResumedRow>& resumed,
                         const std::vector<std::pair<Design, Eigen::MatrixXd>>& derivatives,
                         StartSink& out);

}  // namespace beamrail
