// Design optimization with NLopt: any algorithm by name, objective (minimize, maximize, or
// least-squares targets), inequality constraints on responses, finite-difference gradients
// evaluated in parallel, several starts from Latin-hypercube points in parallel, and a history
// that doubles as a cache so that an interrupted run resumes by replaying its evaluations.
#pragma once

#include "optimizer/batch/run_settings.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {

// Runs the optimization of study.design; writes history.csv, best.json, best_scene.json and
// summary.json. Returns the exit status (1 when no feasible design was found).
int run_optimize(const Study& study, const RunSettings& settings);

}  // namespace beamrail
