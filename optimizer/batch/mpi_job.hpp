// A beamrail run spread over the ranks of an MPI job (`mpirun -n R beamrail run ...`, or a
// cluster's `srun`). Every rank starts the same command; rank 0 alone reads the command line,
// reads and writes files and prints; it sends the study (as read, its scene inlined) to the other
// ranks, and then hands designs out to them one at a time, keeping each rank `threads` + 1
// designs ahead, while evaluating designs with its own threads. The other ranks only evaluate
// the designs they are sent and send the outcomes back; they never touch the results folder.
// Outside an MPI launcher, or in a build without MPI, a process is a job of one rank and MPI is
// never initialized.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace beamrail {

class BatchExecutor;
struct Study;

// What a task is: the other ranks run it by its kind.
enum class TaskKind : int32_t {
  kOptimizationStart = 1,  // batch/start_task.hpp
  kPrecisionRun = 2,       // batch/work_precision.hpp
};

// Tasks spread whole over the ranks (an optimization start each): byte strings in, messages
// along the way and a result out (batch/start_task.hpp).
struct TaskCallbacks {
  // Runs a task on rank 0, handing its messages to `send`.
  std::function<std::vector<char>(const std::vector<char>& task,
                                  const std::function<void(std::vector<char>)>& send,
                                  const std::atomic<bool>& cancel)>
      run_here;
  // A message of task `task` (called one call at a time); false stops the batch: no task starts
  // after it and the running ones are cancelled.
  std::function<bool(long task, const std::vector<char>& message)> message;
  // The result of task `task`, run on `rank` (called one call at a time); false stops the batch
  // as `message` does.
  std::function<bool(long task, int rank, const std::vector<char>& result)> finished;
};

class MpiJob {
 public:
  // Joins the MPI job when the environment shows that an MPI launcher started this process
  // (OMPI_COMM_WORLD_SIZE, PMIX_RANK or PMI_RANK is set, and the build has MPI).
  MpiJob(int* argc, char*** argv);
  // Rank 0 tells the other ranks to stop; then every rank leaves MPI.
  ~MpiJob();
  MpiJob(const MpiJob&) = delete;
  MpiJob& operator=(const MpiJob&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }

  // Ranks other than 0: evaluates what rank 0 sends until it says stop. A design that fails is
  // an outcome sent back, not an error of the rank: the rank's process ends with status 0
  // (cli/main.cpp).
  void serve();

  // Rank 0: an executor over every rank of the job, each evaluating `threads` designs at once.
  std::unique_ptr<BatchExecutor> executor(int threads);

  // Rank 0: runs `tasks` (optimization starts, work-precision runs) of `kind` on every rank of the
  // job, rank 0 included, one at a time per rank, each with `threads` threads, handed out in order
  // as ranks become free. After a stop request or a stop by `callbacks.message` no task starts, and
  // the tasks under way are cancelled (they end early and report). Returns, per task, whether it
  // ran.
  std::vector<bool> run_tasks(const Study& study, int threads, TaskKind kind,
                              const std::vector<std::vector<char>>& tasks,
                              const TaskCallbacks& callbacks);

  // Rank 0: whether the study has been sent to the other ranks (it is sent once, with the first
  // batch; every batch of the run evaluates the same study).
  bool study_sent = false;

 private:
  int rank_ = 0;
  int size_ = 1;
  bool initialized_ = false;
};

// The job of this process while main's MpiJob lives; nullptr before and after, and in tests.
MpiJob* mpi_job();

// Whether this build can join MPI jobs.
bool mpi_available();

}  // namespace beamrail
