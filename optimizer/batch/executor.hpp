// Evaluating a batch of designs: the seam between what a study does with its designs (a sweep
// writes them as rows) and where they are evaluated (threads of this process, or the ranks of an
// MPI job: batch/mpi_job.hpp). An executor computes and hands results back; it writes no file and
// prints nothing.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "optimizer/batch/run_settings.hpp"
#include "optimizer/batch/sampling.hpp"
#include "optimizer/run/designs.hpp"

namespace beamrail {

// Receives the outcome of designs[index]. Called one call at a time (never concurrently), from
// any thread, in any order. Returning false stops the batch: no design starts after it.
using DesignDone = std::function<bool(long index, const DesignOutcome& outcome)>;

// What an executor measured of the batches it ran.
struct ExecutorStats {
  std::vector<long> designs_per_rank;  // outcomes handed back from each rank
  // Rank 0's CPU time spent scheduling (sending designs, polling for, receiving and unpacking
  // outcomes; not evaluating, not the `done` callback) [s]; 0 for threads of one process.
  double scheduler_seconds = 0.0;
  // Rank 0's CPU time spent polling for outcomes while none came [s].
  double polling_seconds = 0.0;
};

class BatchExecutor {
 public:
  virtual ~BatchExecutor() = default;

  // Evaluates every design of `designs` with `evaluator` (whose study every rank evaluates the
  // same way) and hands each outcome to `done`. No design starts after a stop request
  // (core/analysis/stop_request.hpp) or after `done` returned false; an evaluation that a stop
  // request cut short is handed over with Status::kInterrupted. Returns when every design started
  // has been handed over. Never throws: a design whose evaluation throws is a kFailed outcome.
  virtual void evaluate(const DesignEvaluator& evaluator, const std::vector<Design>& designs,
                        const DesignDone& done) = 0;

  // The processes (MPI ranks) that evaluate designs, and the threads that each of them uses.
  virtual int ranks() const = 0;
  virtual int threads() const = 0;

  virtual ExecutorStats stats() const = 0;
};

// The threads of this process: an OpenMP loop that hands out one design at a time.
class ThreadExecutor : public BatchExecutor {
 public:
  explicit ThreadExecutor(int threads) : threads_(threads) {}
  void evaluate(const DesignEvaluator& evaluator, const std::vector<Design>& designs,
                const DesignDone& done) override;
  int ranks() const override { return 1; }
  int threads() const override { return threads_; }
  ExecutorStats stats() const override { return stats_; }

 private:
  int threads_;
  ExecutorStats stats_{{0}, 0.0, 0.0};
};

// Evaluates one design, a thrown exception (of any type) becoming a kFailed outcome.
DesignOutcome evaluate_design(const DesignEvaluator& evaluator, const Design& x);

// The executor of a batch of `work` designs run with `settings`: the ranks of the MPI job when
// this process is rank 0 of a job of several (each with -j threads, default 1), else threads of
// this process (batch_threads).
std::unique_ptr<BatchExecutor> make_executor(const RunSettings& settings, long work);

}  // namespace beamrail
