// Whether an explicit Runge-Kutta table at a fixed step (IntegratorOptions::fixed_step, method
// "erk") is stable for the scene: nothing estimates such a run's error, and beyond the table's
// stability region its fastest modes grow without bound while the run reports success (a 1 ms
// step on a tip-body cantilever ended with 100 times the energy it started with). Checked at the
// start (the linearization at the initial state: a structure that stiffens as it moves is not
// covered).
#pragma once

#include <string>

#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// The largest stiffness-proportional damping of the scene's elements [s].
double largest_damping(const Model& model);

// Mode growth over a run beyond which a fixed explicit step is refused: the fastest modes would
// more than double.
inline constexpr double kFixedStepMaxGrowth = 2.0;

struct FixedStepStability {
  bool checked = false;      // false when the fastest mode could not be computed
  double fastest = 0.0;      // its angular frequency at the initial state [rad/s]
  double growth = 1.0;       // the largest growth of a mode up to it over the run
  double stable_step = 0.0;  // the longest step whose growth stays within kFixedStepMaxGrowth [s]
};

// The stability of the explicit ARKODE table `arkode_table` (an ARKODE ERK table name) at the
// fixed step h over `duration` for the scene at the state y0 (13 states per free body), its
// undamped modes damped by the stiffness-proportional damping (largest_damping).
FixedStepStability fixed_step_stability(const Model& model, Data& data, const double* y0, double t0,
                                        const std::string& arkode_table, double h, double duration);

}  // namespace beamrail
