// Parameter sweeps (grid, list, Latin hypercube): every design evaluated in parallel (threads of
// one process or the ranks of an MPI job), one row of samples.csv per design in index order.
//
// sweep() computes and hands each design's outcome on as it ends; output/sweep_report.hpp writes
// samples.csv (and reads it back for --resume) and summary.json; cli/batch_commands.hpp joins the
// two, prints and returns the exit status.
#pragma once

#include <functional>
#include <set>
#include <vector>

#include "optimizer/batch/executor.hpp"
#include "optimizer/batch/run_settings.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {

// What a sweep did (this run: the designs of an earlier run are not counted).
struct SweepRun {
  long designs = 0;                    // of the plan
  long evaluated = 0;                  // now, with an outcome handed on
  long failed = 0, with_warnings = 0;  // of them
  int ranks = 1, threads = 1;
  ExecutorStats stats;
  double wall_seconds = 0.0;
};

// Evaluates the designs of study.design whose index is not in `done`; each outcome goes to `row`
// (index, design, outcome; one call at a time, in any order). A design cut short by a stop
// request is not handed on; `row` returning false starts no more designs. `shown_failed`: the
// failed designs of an earlier run, for the progress line.
SweepRun sweep(const Study& study, const DesignEvaluator& evaluator, const RunSettings& settings,
               const std::set<long>& done, long shown_failed,
               const std::function<bool(long, const Design&, const DesignOutcome&)>& row);

}  // namespace beamrail
