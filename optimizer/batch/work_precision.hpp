// Work-precision studies: the study's transient analysis run by every listed method at every
// tolerance, each compared with a tight reference run; the measured speed-accuracy trade.
#pragma once

#include "optimizer/batch/run_settings.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {

// Writes work_precision.csv (method, rtol, atol, error vs the reference, wall s, steps, rhs and
// Jacobian evaluations, status) and summary.json. Runs one after another, so that timings are not
// shared with other runs. Returns the exit status.
int run_work_precision(const Study& study, const RunSettings& settings);

}  // namespace beamrail
