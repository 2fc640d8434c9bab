// The files of a sensitivity study (docs/study_files.md "Sensitivities"): sensitivities.csv and
// summary.json. Writing only: the derivatives are computed by batch/sensitivity_study.
#pragma once

#include <chrono>

#include "optimizer/batch/sensitivity_study.hpp"

namespace beamrail {

// Writes sensitivities.csv and summary.json and prints the result; `start`: when the study
// started (its wall time). Returns the exit status: 0, or 1 (the design, its derivatives or the
// check failed, a write error).
int report_sensitivity(const Study& study, const RunSettings& settings,
                       const SensitivityResult& result,
                       std::chrono::steady_clock::time_point start);

}  // namespace beamrail
