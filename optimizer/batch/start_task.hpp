// An optimization start as a task of an MPI job (batch/mpi_job.hpp): the start's number, point
// and constraint scales with the designs it may replay (its rows of history.csv on --resume) in,
// its rows and derivatives out as they are made, its StartResult at the end; all as byte strings
// (batch/wire.hpp). Computing only.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "optimizer/batch/start_runner.hpp"

namespace beamrail {

// A design the start may take from its cache, with its derivatives when they are known (null
// jacobian with has_jacobian: it has none).
struct KnownDesign {
  Design x;
  DesignOutcome outcome;
  bool has_jacobian = false;
  std::shared_ptr<const Eigen::MatrixXd> jacobian;
};

std::vector<char> pack_start_task(const StartTask& task, const std::vector<KnownDesign>& known);

// Runs a packed start task with `threads` threads on the evaluator's study, handing each row and
// derivative to `send` as a message; returns the packed StartResult. Never throws.
std::vector<char> run_start_task(const DesignEvaluator& evaluator, int threads,
                                 const std::vector<char>& task,
                                 const std::function<void(std::vector<char>)>& send,
                                 const std::atomic<bool>& cancel);

// The packed result of a start task that could not run (NLOPT_FAILURE with `why`).
std::vector<char> failed_start_task(const std::vector<char>& task, const std::string& why);

// Hands a message of run_start_task to the sink.
void unpack_start_message(const std::vector<char>& message, StartSink& sink);
StartResult unpack_start_result(const std::vector<char>& result);

}  // namespace beamrail
