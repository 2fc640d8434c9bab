// The equations of motion as SUNDIALS sees them: right-hand side, exact Jacobian (dense or sparse
// CSC with the structure of the model's topology), and the quaternion projection. Callbacks never
// throw: an exception is recorded in the context and reported as an unrecoverable failure.
// Non-finite forces are a recoverable failure (the integrator retries with a smaller step: a Newton
// trial state may be far out) until kNonFiniteLimit of them pile up within one call of the
// integrator; then the motion has diverged and the right-hand side fails unrecoverably.
#pragma once

#include <nvector/nvector_serial.h>
#include <sundials/sundials_matrix.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/analysis/sparse_structure.hpp"
#include "core/analysis/stop_request.hpp"
#include "core/model/data.hpp"
#include "core/model/dynamics.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// Non-finite right-hand sides tolerated within one call of the integrator (one output interval).
inline constexpr long kNonFiniteLimit = 1000;

struct OdeContext {
  OdeContext(const Model& m, Data& d) : model(m), data(d) {}
  const Model& model;
  Data& data;
  std::vector<Mat13> blocks;
  SparseStructureCache* structure_cache = nullptr;   // where the sparse solver gets its structure
  std::shared_ptr<const SparseStructure> structure;  // set when the sparse solver is used
  std::string callback_error;                        // an exception caught inside a callback
  // Wall-clock budget: past this moment the right-hand side fails unrecoverably.
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
  bool timed_out = false;
  bool interrupted = false;        // a stop was requested (stop_request.hpp) or cancel set
  long nonfinite_evaluations = 0;  // in the current call of the integrator
  std::string divergence;          // why the run was ended as diverged (non-finite forces)
  // This run's own stop request (TransientOptions::cancel); nullptr: none.
  const std::atomic<bool>* cancel = nullptr;
  // The last state of the current call with an element outside the range of its law (a
  // recoverable failure of the right-hand side), described: why the integrator gave up, if it
  // did so over failures of the right-hand side.
  std::string out_of_range;
  double out_of_range_t = 0.0;  // its time [s]
  // The time of the last step the integrator accepted (its post-step hook, ode_normalize) [s]:
  // ARKODE's current time is a failed stage's.
  double accepted_t = 0.0;
  // The end of the current stretch between the loads' breakpoints or t_end (the transient
  // analysis sets it): a jump there belongs to the next stretch, so the forces at or past it are
  // those just before it. A step's last stage (c = 1) at the jump once saw the load on: dirk and
  // erk moved before a step load at 10.05 ms (8 % of the motion off; the step before it held the
  // whole load in its last stage and its interpolated outputs).
  double stretch_end = std::numeric_limits<double>::infinity();
  // The breakpoint the current stretch starts from: a method restarted a rounding error before
  // it (an output time of 11 x 0.03 = 0.32999999999999996 against a step at 0.33) sees the jump
  // from its first stage on. Before this, auto ended 2.6 rtol off and a fixed-step DIRK 1.1e-3
  // (the step's first stage had the load off).
  double stretch_start = -std::numeric_limits<double>::infinity();
  // Called with each state an integrator accepts (its time and the model's states), between the
  // steps: the analysis watches the element laws' range there (DeformationCheck), not only at the
  // output rows, which a swing can pass between. Empty: nothing is called. Every method calls it:
  // ARKODE's after each step (ode_normalize), CVODE's where it asks for the error weights of the
  // state it accepted (ode_error_weights), the modal method as it accepts a step.
  std::function<void(double t, const double* y)> step_taken;
  // Set while the modal method calls step_taken: its steps, exact on the linear motion, may span
  // many periods, and its own bounds see to its path between them (modal_step_bounds.hpp), so
  // the path between its steps is not interpolated.
  bool path_bounded = false;
  // CVODE's error weights 1 / (rtol |y_i| + atol), computed by its integrator (CVodeWFtolerances):
  // CVODE asks for them once per accepted step, with that step's state. Returns 0, or -1 where a
  // weight would be infinite.
  std::function<int(N_Vector y, N_Vector weights)> error_weights;

  // The time the forces are evaluated at for the integrator's time t.
  double force_time(double t) const {
    if (t < stretch_start) return stretch_start;
    return t >= stretch_end ? std::nextafter(stretch_end, -std::numeric_limits<double>::infinity())
                            : t;
  }

  // True, with timed_out or interrupted set, when the run must end now.
  bool should_stop() {
    if (stop_requested() || (cancel && cancel->load(std::memory_order_relaxed))) interrupted = true;
    if (!interrupted && std::chrono::steady_clock::now() > deadline) timed_out = true;
    return interrupted || timed_out;
  }
};

// SUNDIALS callbacks; user_data is an OdeContext*.
int ode_rhs(double t, N_Vector y, N_Vector ydot, void* user_data);
int ode_dense_jacobian(double t, N_Vector y, N_Vector fy, SUNMatrix jac, void* user_data, N_Vector,
                       N_Vector, N_Vector);
int ode_sparse_jacobian(double t, N_Vector y, N_Vector fy, SUNMatrix jac, void* user_data, N_Vector,
                        N_Vector, N_Vector);
// CVODE projection onto |q| = 1 (corrections and error estimate).
int ode_project(double t, N_Vector ycur, N_Vector corr, double eps, N_Vector err, void* user_data);
// After each step of ARKODE methods, which have no projection: q <- q / |q|; then step_taken.
int ode_normalize(double t, N_Vector y, void* user_data);
// CVODE's error weights (OdeContext::error_weights).
int ode_error_weights(N_Vector y, N_Vector weights, void* user_data);

}  // namespace beamrail
