// Design points of sweeps and starting points of optimizations.
#pragma once

#include <vector>

#include "optimizer/study/design_study.hpp"

namespace beamrail {

using Design = std::vector<double>;

// Full factorial grid, the last variable varying fastest (index order of samples.csv).
std::vector<Design> grid_designs(const std::vector<DesignVariable>& variables);

// Latin hypercube: n points, each variable's range cut into n equal strata, one point per
// stratum, strata paired at random; deterministic for a given seed on every platform.
std::vector<Design> latin_hypercube(const std::vector<DesignVariable>& variables, int n,
                                    unsigned long seed);

// The designs a sweep evaluates, in index order.
std::vector<Design> sweep_designs(const DesignStudy& study);

}  // namespace beamrail
