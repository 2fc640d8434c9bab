// Whether an explicit Runge-Kutta table at a fixed step (IntegratorOptions::fixed_step, method
// "erk") is stable for the scene: nothing estimates such a run's error, and beyond the table's
// stability region its fastest modes grow without bound while the run reports success (a 1 ms
// step on a tip-body cantilever ended with 100 times the energy it started with). Checked at the
// start (the linearization at the initial state: a structure that stiffens as it moves is not
// covered).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// The largest stiffness-proportional damping of the scene's elements [s].
double largest_damping(const Model& model);

// The scene's fastest angular frequency at the state y0 (13 states per free body): the largest
// w of K x = w^2 M x there [rad/s]; 0 when it could not be computed.
double fastest_mode(const Model& model, Data& data, const double* y0, double t0);

// The longest step of an adaptive explicit run, as w h of the scene's fastest mode at its start.
// An adaptive run may step far beyond its table's stability where nothing excites the fast
// modes (a scene exactly at rest): its steps stay right, but ARKODE's rows between steps
// (Hermite interpolants of degree 4 and 5) evaluate the forces at interpolated states, where
// the stiff forces turn the rounding of the interpolation into motion that grows as (w h)^2. A
// flexible pendulum at rest for 0.2 s (w 1.0e7 rad/s on its joint; Verner 8(7) at rtol 1e-11,
// 7 steps of up to 0.05 s) wrote rows with 7e-7 m of motion and 5.18 J of energy, silent. With
// steps at w h = 8, 30, 100, 1,000 and 1e5 the rows moved 5.6e-17, 5.6e-16, 6.1e-15, 5.9e-13 and
// 2.4e-9 m (1e-18 (w h)^2 of its 0.6 m). So w h stays below sqrt(kExplicitRowsRounding rtol /
// eps), where that pendulum's rows keep within 5e-5 rtol (21 at rtol 1e-11, 6,700 at 1e-6),
// and at least kExplicitShortestWh. A run in motion does not come near it: beyond w h = 4 both
// default tables grow any fast motion by more than twice per step (|R(4i)| 3.7 for
// Dormand-Prince 5(4), 2.3 for Verner 8(7)), which their error estimates refuse.
inline constexpr double kExplicitRowsRounding = 1e-2;
inline constexpr double kExplicitShortestWh = 4.0;
inline double explicit_longest_wh(double rtol) {
  return std::max(kExplicitShortestWh,
                  std::sqrt(kExplicitRowsRounding * rtol / std::numeric_limits<double>::epsilon()));
}

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
