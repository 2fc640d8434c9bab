// Static analysis (docs/model.md "Analyses"): equilibrium of all free bodies under gravity and the
// loads at a given time, geometrically nonlinear. The loads are raised by load steps (below) or,
// under arc-length control, along the load-displacement path (core/analysis/static_path.cpp).
// Newton's method on 6 unknowns per free body (centre displacement and rotation increment) with the
// exact tangent by automatic differentiation (factored by KLU with the topology's shared symbolic
// analysis), full Newton steps (halved only when they make the forces non-finite), and automatic
// load stepping when a full load step fails (also when it found no equilibrium: up to 4 halvings in
// a row before that is the answer). The tangent counts as singular against the structure's own
// scales (pivot_floor in the .cpp: a chain of n elements has physical pivot ratios near 1 / (4
// n^3)).
//
// What a converged result promises (result.ok):
//  - balance: the residual is below tolerance x the load scale, or, where rounding keeps it
//    above that (the stiffness terms of chains of thousands of very short segments cancel
//    beyond double precision), it is at the rounding floor AND the last Newton correction is below
//    kCorrectionTolerance of the displacement (measured: 1e-12 on a 10,000-segment cantilever);
//    then a warning gives how far the element forces are from balance when that exceeds 1e-6 of
//    the load;
//  - stability: the tangent stiffness at the equilibrium has no negative direction (a column
//    loaded beyond its buckling load, whose straight state is an unstable equilibrium, fails);
//    under torques of fixed direction or follower loads (non-conservative, a non-symmetric
//    tangent) no small
//    vibration grows: no negative real or complex eigenvalue of K x = lambda M x (all of them up
//    to 120 degrees of freedom; beyond, the 12 nearest zero and the sign of det K);
//  - range: every element is inside the range of its law (core/analysis/deformation_check.hpp),
//    and no element's angles passed pi (where its law repeats) on the way: each Newton iterate
//    turns a body by at most kMaxRotationStep, and an iterate that turns an element by more than
//    kIterateRotationLimit fails the load step (a smaller one is tried).
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "core/analysis/sparse_structure.hpp"
#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// How the loads are raised: by load steps (load control), or along the load-displacement path by
// arc length (the load factor is an unknown: the path passes limit points and snaps; docs/model.md
// "Arc-length control").
enum class StaticControl { kLoad, kArcLength };

struct StaticOptions {
  // Time at which the loads are evaluated [s]; +infinity: each load's final value.
  double time = std::numeric_limits<double>::infinity();
  StaticControl control = StaticControl::kLoad;
  // Arc-length control: the first step's length [m] (rotations count times the structure's
  // characteristic length); 0: a tenth of the linear response to the full loads.
  double arc_length = 0.0;
  int load_steps = 0;         // 0: automatic (one step, subdivided on failure); n: n equal steps
  int max_iterations = 30;    // Newton iterations per load step
  double tolerance = 1e-10;   // residual, relative to the applied load scale
  int max_load_steps = 1000;  // total load increments allowed (including subdivisions)
  double max_seconds = 0.0;   // wall-clock budget [s]; 0: none (result.timed_out when spent)
  // Shares the tangent's sparse pattern and KLU ordering between analyses of one topology
  // (designs); nullptr: this analysis makes its own.
  SparseStructureCache* structure_cache = nullptr;
  // Whether the options can run: true, or false with the first problem in *error. The analysis
  // refuses options that are not valid; the study reader reports them.
  bool IsValid(std::string* error) const;
};

// A converged point of an arc-length path: the load factor and the displacements of the path's
// bodies (StaticResult::path_bodies: centre displacement and rotation vector).
struct StaticPathPoint {
  double load_factor = 0.0;
  double arc_length = 0.0;  // from the start [m]
  int iterations = 0;       // corrector iterations of this point
  std::vector<Vec3> displacement, rotation;
};

struct StaticResult {
  bool ok = false;
  bool timed_out = false;  // stopped by max_seconds
  std::string message;
  double residual_norm = 0.0;    // final scaled residual |R| [N]
  double reference_force = 0.0;  // the load scale the residual is compared with [N]
  double rounding_floor = 0.0;   // what rounding alone leaves in the residual, estimated [N]
  double correction = 0.0;       // last Newton correction / largest displacement (both scaled)
  int iterations = 0;            // Newton iterations over all load steps
  int load_steps = 0;            // load increments taken
  // Tangent directions with no stiffness (solved minimum-norm): a mechanism's at its
  // equilibrium, a structure held by beams the most along its load path.
  int singular_directions = 0;
  int negative_directions = 0;  // of the tangent at the equilibrium (> 0: unstable, not ok)
  int flutter_pairs = 0;  // growing vibration pairs under non-conservative loads (> 0: not ok)
  // Not ok because the loads push a free body or mechanism along a direction without stiffness
  // (a carriage pushed along its rail): no equilibrium exists, whatever the load steps.
  bool no_equilibrium = false;
  double wall_seconds = 0.0;
  std::vector<std::string> warnings;
  // Arc-length control: the path from the unloaded start (the last point the full loads, when
  // reached), the bodies it records (the scene's own free bodies, not a beam's segment bodies;
  // every free body when none is; the first 1000 of them, with a warning) and the first limit
  // point's load factor (the first maximum of the load factor along the path, interpolated; NaN
  // when none was passed).
  std::vector<StaticPathPoint> path;
  std::vector<int> path_bodies;
  double limit_load_factor = std::numeric_limits<double>::quiet_NaN();
};

// At the rounding floor, a Newton correction below this fraction of the displacement has
// converged (it is applied, and the iterations stop).
inline constexpr double kCorrectionTolerance = 1e-6;
// The largest rotation of a body in one Newton iterate, and the largest relative rotation of an
// element in any iterate [rad]: an element passing pi would exceed the latter on the way, since
// one iterate changes it by at most 2 kMaxRotationStep < pi - kIterateRotationLimit.
inline constexpr double kMaxRotationStep = 0.5;
inline constexpr double kIterateRotationLimit = 2.0;

// Solves for equilibrium starting from the initial configuration; on return data.pose holds the
// equilibrium (or the last converged state on failure) and data.wrench the residual. Never throws.
StaticResult solve_static(const Model& model, const StaticOptions& options, Data& data);

}  // namespace beamrail
