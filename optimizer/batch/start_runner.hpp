// One start of a multi-start optimization: an NLopt run from a start point, evaluating the designs
// NLopt asks for (in parallel where it asks for several at once: the points of a finite-difference
// gradient), each start with its own design budget. Designs are looked up in a cache first, so
// that a resumed run replays its path from the history without evaluating it again. Computing
// only: every row and derivative is handed to a StartSink; no files, no printing.
#pragma once

#include <nlopt.h>

#include <Eigen/Core>
#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "optimizer/batch/executor.hpp"
#include "optimizer/batch/optimization_problem.hpp"

namespace beamrail {

// A row of history.csv: the design a start evaluated as its `evaluation`-th (1-based).
struct OptimizationRecord {
  int start = 0, evaluation = 0;
  Design x;
  DesignOutcome outcome;
  double objective = kPenalty;
  bool feasible = false;
};

// What evaluating designs cost.
struct EvaluationCost {
  long simulated = 0;  // designs evaluated (a design evaluated again for its derivatives counts)
  long failures = 0;   // of them, not ok
  long exact_gradients = 0;                    // designs evaluated with their exact derivatives
  long gradient_fallbacks = 0;                 // ok designs whose derivatives could not be computed
  std::string fallback_reason;                 // the first of them
  std::set<std::string> sensitivity_warnings;  // at most 20
  void add(const EvaluationCost& other);
};

// How a start ended.
struct StartResult {
  int index = 0;  // 1-based
  nlopt_result result = NLOPT_FAILURE;
  std::string message;   // NLopt's own message on an error, or why the start could not run
  bool stopped = false;  // stopped by beamrail (a stop request, or the batch stopped)
  // Stopped because NLopt's next call needed more designs than the budget had left
  // (budget_needed of them); result is then MAXEVAL_REACHED.
  bool budget_spent = false;
  long budget_needed = 0;
  int nlopt_evaluations = 0;
  double objective_scale = 1.0;  // NLopt sees objective / this: |objective| at the start point
  long designs = 0;              // distinct designs of the start (its rows of history.csv)
  int rank = 0;                  // the MPI rank that ran it
  EvaluationCost cost;
};

// The designs known to the starts that share it (this run's and those read back on --resume), and
// their exact derivatives when evaluated with them (null: the design has none). Thread-safe.
class DesignCache {
 public:
  std::optional<DesignOutcome> find(const Design& x) const;
  void add(const Design& x, const DesignOutcome& o);
  // Whether x's derivatives are known (*jacobian null when x has none).
  bool find_jacobian(const Design& x, std::shared_ptr<const Eigen::MatrixXd>* jacobian) const;
  void set_jacobian(const Design& x, std::shared_ptr<const Eigen::MatrixXd> jacobian);

 private:
  mutable std::mutex mutex_;
  std::map<Design, DesignOutcome> outcomes_;
  std::map<Design, std::shared_ptr<const Eigen::MatrixXd>> jacobians_;
};

// Receives a start's rows and derivatives as they are made: calls may come from several starts at
// once (the sink serializes them).
class StartSink {
 public:
  virtual ~StartSink() = default;
  virtual void record(const OptimizationRecord& r) = 0;
  virtual void derivatives(const Design& x, const Eigen::MatrixXd& jacobian) = 0;
  // False once the sink can take no more (a write error): the starts then stop.
  virtual bool good() const { return true; }
};

// What a start needs besides the problem: its number, start point, and the constraints' scales
// (NLopt sees constraint j as its violation in the response's units over scales[j]).
struct StartTask {
  int index = 1;
  Design x0;
  std::vector<double> constraint_scales;
};

// Runs a start with `threads` threads for the designs NLopt asks for at once, or with `designs`
// for them when given (the ranks of an MPI job; designs evaluated with their derivatives stay
// here). Stops when a stop is requested (core/analysis/stop_request.hpp) or `cancel` is set: a
// design cut short is neither cached nor recorded. Never throws.
StartResult run_start(const OptimizationProblem& problem, const DesignEvaluator& evaluator,
                      const StartTask& task, DesignCache& cache, int threads, StartSink& sink,
                      const std::atomic<bool>& cancel, BatchExecutor* designs = nullptr);

// Evaluates x into the cache unless it is there (with its derivatives for exact gradients; they
// go to the sink), numbered in no start: the design the constraints' scales come from.
DesignOutcome evaluate_into_cache(const OptimizationProblem& problem,
                                  const DesignEvaluator& evaluator, const Design& x,
                                  DesignCache& cache, StartSink& sink, EvaluationCost* cost);

}  // namespace beamrail
