// Sensitivity studies (docs/study_files.md "Sensitivities"): the derivative of every response with
// respect to every variable at the study's own design -> sensitivities.csv
// (response,variable,value,derivative; with "check": the central difference of the responses and
// the relative difference of the two).
#pragma once

#include "optimizer/batch/run_settings.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {

// Runs the sensitivity study of study.design; writes sensitivities.csv and summary.json. Returns
// the exit status.
int run_sensitivity(const Study& study, const RunSettings& settings);

}  // namespace beamrail
