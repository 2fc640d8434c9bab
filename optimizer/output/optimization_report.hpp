// The files of an optimization (docs/study_files.md "Outputs"): history.csv (a row per design
// each start evaluated) and derivatives.csv (exact gradients), written as rows come and read back
// by --resume; best.json, best_scene.json and summary.json written from what the run did
// (batch/optimize.hpp). Writing only: no design is evaluated here, and nothing is printed
// (cli/batch_commands.hpp prints).
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "optimizer/batch/optimize.hpp"
#include "optimizer/output/batch_table.hpp"
#include "optimizer/output/run_outcome.hpp"
#include "optimizer/run/status.hpp"

namespace beamrail {

// The columns of history.csv: start, evaluation, the variables, the responses, objective,
// feasible, status, warnings, wall_s, message.
CsvRow history_header(const OptimizationProblem& problem);
CsvRow history_row(const OptimizationRecord& r);

class OptimizationFiles : public StartSink {
 public:
  OptimizationFiles(const OptimizationProblem& problem, const RunSettings& settings)
      : problem_(problem), settings_(settings) {}

  // Removes a best design of an earlier run, and opens history.csv (and derivatives.csv for exact
  // gradients) fresh or, with --resume, reading back their rows; anything but kOk with error()
  // saying why.
  BatchTable::Opened open();
  const std::vector<ResumedRow>& resumed() const { return resumed_; }
  const std::vector<std::pair<Design, Eigen::MatrixXd>>& resumed_derivatives() const {
    return derivatives_read_;
  }

  void record(const OptimizationRecord& r) override;
  void derivatives(const Design& x, const Eigen::MatrixXd& jacobian) override;
  bool good() const override { return !failed_; }

  // Rewrites the tables in (start, evaluation) and design order; false with error() on failure.
  bool finalize();
  const std::string& error() const { return error_; }

 private:
  const OptimizationProblem& problem_;
  const RunSettings& settings_;
  BatchTable history_, derivatives_;
  std::vector<ResumedRow> resumed_;
  std::vector<std::pair<Design, Eigen::MatrixXd>> derivatives_read_;
  bool failed_ = false;
  std::string error_;
};

// What report_optimization wrote: the outcome (kOk; kFailed, also when no design is feasible;
// kInterrupted; kWriteError), summary.json's status and message, the warnings the run added to
// the study's, and the best feasible design evaluated (the result when kOk).
struct OptimizationReport {
  RunOutcome outcome;
  RunStatus status = RunStatus::kOk;
  std::vector<std::string> warnings;
  std::optional<OptimizationRecord> best;
};

// Writes summary.json, and best.json and best_scene.json when the optimization ended ok.
// `table_error`: why history.csv could not be written ("" when it was).
OptimizationReport report_optimization(const OptimizationProblem& problem,
                                       const DesignEvaluator& evaluator,
                                       const RunSettings& settings, const OptimizationRun& run,
                                       const std::string& table_error);

}  // namespace beamrail
