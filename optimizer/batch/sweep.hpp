// Parameter sweeps (grid, list, Latin hypercube): every design evaluated in parallel, one row of
// samples.csv per design in index order.
#pragma once

#include "optimizer/batch/run_settings.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {

// Runs the sweep of study.design; writes samples.csv and summary.json. Returns the exit status.
int run_sweep(const Study& study, const RunSettings& settings);

}  // namespace beamrail
