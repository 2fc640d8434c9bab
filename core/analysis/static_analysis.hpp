// Static analysis (DESIGN.md §2): equilibrium of all free bodies under gravity and the loads at a
// given time, geometrically nonlinear. Newton's method on 6 unknowns per free body (centre
// displacement and rotation increment) with the exact tangent by automatic differentiation
// (factored by KLU with the topology's shared symbolic analysis), a backtracking line search, and
// automatic load stepping when a full step fails.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "core/analysis/sparse_structure.hpp"
#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

struct StaticOptions {
  // Time at which the loads are evaluated [s]; +infinity: each load's final value.
  double time = std::numeric_limits<double>::infinity();
  int load_steps = 0;         // 0: automatic (one step, subdivided on failure); n: n equal steps
  int max_iterations = 30;    // Newton iterations per load step
  double tolerance = 1e-10;   // residual, relative to the applied load scale
  int max_load_steps = 1000;  // total load increments allowed (including subdivisions)
  // Shares the tangent's sparse pattern and KLU ordering between analyses of one topology
  // (designs); nullptr: this analysis makes its own.
  SparseStructureCache* structure_cache = nullptr;
};

struct StaticResult {
  bool ok = false;
  std::string message;
  double residual_norm = 0.0;    // final scaled residual |R| [N]
  double reference_force = 0.0;  // the load scale the residual is compared with [N]
  int iterations = 0;            // Newton iterations over all load steps
  int load_steps = 0;            // load increments taken
  int singular_directions = 0;   // tangent directions with no stiffness (solved minimum-norm)
  double wall_seconds = 0.0;
  std::vector<std::string> warnings;
};

// Solves for equilibrium starting from the initial configuration; on return data.pose holds the
// equilibrium (or the last converged state on failure) and data.wrench the residual. Never throws.
StaticResult solve_static(const Model& model, const StaticOptions& options, Data& data);

}  // namespace beamrail
