// The files of a sensitivity study (docs/study_files.md "Sensitivities"): sensitivities.csv and
// summary.json. Writing only: the derivatives are computed by batch/sensitivity_study, and
// nothing is printed (cli/batch_commands.hpp prints).
#pragma once

#include <chrono>

#include "optimizer/batch/sensitivity_study.hpp"
#include "optimizer/output/run_outcome.hpp"
#include "optimizer/run/status.hpp"

namespace beamrail {

// What report_sensitivity wrote: the outcome (kOk; kFailed: the design, its derivatives or the
// check failed, or the table could not be written; kInterrupted; kWriteError: summary.json could
// not be written), summary.json's status and warnings (the study's input warnings first), and what
// the result line says.
struct SensitivityReport {
  RunOutcome outcome;
  RunStatus status = RunStatus::kOk;
  std::vector<std::string> warnings;
  double largest_relative_difference = 0.0;  // with "check"
  double wall_seconds = 0.0;
};

// Writes sensitivities.csv and summary.json; `start`: when the study started (its wall time).
SensitivityReport report_sensitivity(const Study& study, const RunSettings& settings,
                                     const SensitivityResult& result,
                                     std::chrono::steady_clock::time_point start);

}  // namespace beamrail
