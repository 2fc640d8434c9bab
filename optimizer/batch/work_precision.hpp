// Work-precision studies: the study's transient analysis run by every listed method at every
// tolerance, each compared with a tight reference run; the measured speed-accuracy trade.
//
// measure_work_precision() computes: the reference run, then the runs one after another in one
// process, or under mpirun one at a time per rank (rank 0 included), each rank comparing its run
// with the reference trajectory rank 0 sends it. output/work_precision_report.hpp writes the table
// and summary.json; cli/batch_commands.hpp joins the two, prints and returns the exit status.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "optimizer/run/status.hpp"
#include "optimizer/run/trajectory.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {

// One run of a work-precision study: a method at a tolerance, measured against the reference.
struct PrecisionRun {
  long index = 0;  // in plan order: by method, then by rtol
  std::string method;
  double rtol = 0.0, atol = 0.0;
  double error = std::numeric_limits<double>::quiet_NaN();  // centres, against the reference
  double rotation_error = std::numeric_limits<double>::quiet_NaN();  // orientations, likewise
  SolverStats stats;
  std::string linear_solver;
  bool ok = false, timed_out = false;
  bool interrupted = false;  // cut short by a stop request: not a measurement
  std::string status() const {
    return status_name(ok ? Status::kOk : timed_out ? Status::kTimeout : Status::kFailed);
  }
  // The larger of the errors that could be measured (NaN when neither could): what a run is
  // judged by against the target error, so that a run wrong only in its rotations is not chosen.
  double larger_error() const {
    if (std::isnan(error)) return rotation_error;
    if (std::isnan(rotation_error)) return error;
    return std::max(error, rotation_error);
  }
};

// The reference run: the plan's reference integrator on the study's transient analysis.
struct PrecisionReference {
  TransientResult result;
  Trajectory trajectory;
  // The structure analyses of the model, which every run integrates.
  std::shared_ptr<SparseStructureCache> structures = std::make_shared<SparseStructureCache>();
};
PrecisionReference run_reference(const Study& study);

struct WorkPrecisionResult {
  std::vector<PrecisionRun> runs;  // the runs measured, in plan order
  long planned = 0;
  bool interrupted = false;  // a run was cut short by a stop request
  int ranks = 1;
  std::vector<long> runs_per_rank;  // under mpirun
};

// Runs the plan's runs against a reference that succeeded; each measured run goes to `done` as it
// ends (one call at a time, in plan order in one process, in any order under mpirun); after a
// stop request or `done` returning false no run starts.
WorkPrecisionResult measure_work_precision(const Study& study, const PrecisionReference& reference,
                                           const std::function<bool(const PrecisionRun&)>& done);

// Runs the plan's run `index` (plan order) of `study` against the reference trajectory.
// `structures`: the structure analyses the runs share (the model's), or nullptr.
PrecisionRun measure_run(const Study& study, long index, const Trajectory& reference,
                         SparseStructureCache* structures);

// An MPI task of a work-precision run (batch/mpi_job.hpp): the run's index and the reference
// trajectory in, the packed PrecisionRun out.
std::vector<char> pack_precision_task(long index, const Trajectory& reference);
// `study` null (a rank that could not load it): a failed run. `structures` null: the rank's own.
std::vector<char> run_precision_task(const Study* study, const std::vector<char>& task,
                                     SparseStructureCache* structures);
PrecisionRun unpack_precision_run(const std::vector<char>& bytes);

}  // namespace beamrail
