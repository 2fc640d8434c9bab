// A transient's verification rerun (its trajectory kept to compare with the run's;
// optimizer/run/transient_analysis.cpp weighs it, transient_checks.hpp says when one is due), run
// after the run or on its own thread beside it.
#pragma once

#include <atomic>
#include <exception>
#include <thread>

#include "core/analysis/transient.hpp"
#include "core/model/model.hpp"
#include "optimizer/run/trajectory.hpp"

namespace beamrail {

// The output rows of a transient, its first state included.
long output_rows(const TransientOptions& options);

// A verification rerun: its result and its bodies' samples at the outputs of the run it verifies.
struct Rerun {
  TransientResult result;
  Trajectory samples;
};

// Runs `tight` (the tighter options of a run with `options`), keeping its samples.
Rerun rerun(const Model& model, const TransientOptions& tight, const TransientOptions& options);

// A verification rerun run on its own thread beside the run it verifies
// (EvaluationOptions::verify_beside): the two take the longer one's time rather than their sum.
// The rerun shares only the model (immutable) and the structure cache (thread-safe); its products
// run on its thread alone. Destroyed before take(), it cancels the rerun and waits for it.
class RerunBeside {
 public:
  RerunBeside(const Model& model, TransientOptions tight, const TransientOptions& options);
  RerunBeside(const RerunBeside&) = delete;
  RerunBeside& operator=(const RerunBeside&) = delete;
  ~RerunBeside();

  // Waits for the rerun; rethrows what it threw.
  Rerun take();

 private:
  std::atomic<bool> cancel_{false};
  TransientOptions tight_;
  Rerun rerun_;
  std::exception_ptr error_;
  std::thread thread_;  // last: started once the rest exists
};

}  // namespace beamrail
