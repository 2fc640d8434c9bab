// Transient analysis (docs/model.md "Analyses"): integrates the equations of motion of the free
// bodies from the Model's initial state with CVODE (BDF, Newton iterations, exact Jacobian by
// automatic differentiation), keeping |q| = 1 by CVODE's projection, and reports a sample at every
// output step.
#pragma once

#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/analysis/sparse_structure.hpp"
#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

enum class JacobianKind { kExact, kFiniteDifference };
enum class LinearSolverKind { kAuto, kDense, kSparse };

// The integrator families: CVODE's BDF and Adams, ARKODE's diagonally implicit and explicit
// Runge-Kutta methods, the modal integrator (core/analysis/modal_integrator.hpp) and auto, which
// chooses among them per scene and per phase (core/analysis/auto_integrator.hpp).
enum class IntegratorMethod { kBdf, kAdams, kDirk, kErk, kModal, kAuto };

// The method's name in study files and tables: "bdf", "adams", "dirk", "erk", "modal", "auto".
const char* method_name(IntegratorMethod method);
// The method named `name`, nullopt for any other text.
std::optional<IntegratorMethod> method_from_name(const std::string& name);

// Defaults of the integrator families (measured: see README "Speed and accuracy, measured").
inline constexpr const char* kDefaultDirkTable = "ARK548L2SA_DIRK_8_4_5";
inline constexpr const char* kDefaultErkTable = "DORMAND_PRINCE_7_4_5";
// linear_solver "auto": dense below this many states, sparse (KLU) from it. Measured on the
// reference cantilever (BDF, rtol 1e-6): equal at 1 body (13 states), sparse 1.3x faster at 2
// bodies, 1.8x at 4 and 5, 4x at 10.
inline constexpr long kSparseStateThreshold = 26;

struct IntegratorOptions {
  // bdf | adams (CVODE), dirk | erk (ARKODE), modal, auto (core/analysis/auto_integrator.hpp).
  // A study's transient defaults to auto (optimizer/study/analysis_specs.cpp); this struct to bdf.
  IntegratorMethod method = IntegratorMethod::kBdf;
  std::string table;   // dirk/erk: ARKODE Butcher table name ("" = default)
  double rtol = 1e-6;  // relative tolerance
  double atol = 1e-9;  // absolute tolerance (states in m, -, m/s, rad/s)
  JacobianKind jacobian = JacobianKind::kExact;
  LinearSolverKind linear_solver = LinearSolverKind::kAuto;
  int max_order = 5;                       // BDF order limit 1..5 (Adams: 1..12)
  bool stability_limit_detection = false;  // CVODE's BDF stability limit detection
  double max_step = 0.0;                   // [s]; 0: no limit
  double initial_step = 0.0;               // [s]; 0: the integrator's estimate
  // dirk, erk: every step this long [s] (the last before a breakpoint or t_end shorter), no error
  // control: rtol and atol only set the implicit stages' Newton tolerance. For references whose
  // error is measured by halving the step (an undamped stiff scene makes an adaptive implicit
  // method resolve modes an L-stable fixed step damps). 0: adaptive steps.
  double fixed_step = 0.0;
  long max_steps = 10000000;  // step budget of the whole run (all output steps)
  long steps_before = 0;      // steps of the run's earlier phases (auto), counted in max_steps
  // modal: the configuration linearized about: "static" (the equilibrium under the loads at
  // t = 0), "initial" (the initial state), "" (static when that equilibrium is found within
  // kModalIntegratorMaxRotation of the initial state, else initial, with a warning).
  std::string about;
  // modal: the rotation from the linearization past which the run stops [rad]; 0:
  // kModalIntegratorMaxRotation. Set by auto, which relinearizes there.
  double max_rotation = 0.0;
  // modal, auto: the band integrated [Hz]; the modes above it are quasi-static (their static
  // response kept, their dynamics dropped). 0: every mode.
  double max_frequency_hz = 0.0;
  // modal, auto, with max_frequency_hz 0: choose the band for rtol (core/analysis/modal_band.hpp:
  // the fewest modes whose dropped ringing is estimated within rtol of the motion; study files'
  // "max_frequency_hz": "auto"). auto chooses it itself for large scenes.
  bool choose_band = false;
  // The run's end [s] (run_transient sets it to t_end): a chosen band's estimate sizes the motion
  // of a run shorter than a quarter of the lowest period by what it reaches (modal_band.hpp).
  // 0: unbounded.
  double horizon = 0.0;

  // Whether the options can run: true, or false with the first problem in *error (a tolerance
  // not positive, an order outside the method's range, an option of another method). The
  // transient analysis refuses options that are not valid; the study reader reports them.
  bool IsValid(std::string* error) const;
};

// One phase of a run: from time t on, `method` ran, chosen for `reason` (auto; other methods have
// one phase).
struct MethodPhase {
  double t = 0.0;
  std::string method;  // "modal", "bdf", "dirk ESDIRK547L2SA2_7_4_5", ...
  std::string reason;
  bool relinearized = false;  // a modal phase linearized again as a body turned its limit
};

struct TransientOptions {
  double t_end = 1.0;         // [s]
  double output_step = 0.01;  // [s]
  IntegratorOptions integrator;
  double max_seconds = 0.0;  // wall-clock budget; 0: none. Exceeding it ends the run as a timeout
  // Shares the sparse Jacobian structure and KLU ordering between runs of one topology (designs,
  // reruns); nullptr: this run analyses its own.
  SparseStructureCache* structure_cache = nullptr;
  // The state at t = 0 (dim model.n_states; initial_state_at makes one from a static
  // equilibrium); empty: the model's initial state.
  std::vector<double> initial_state;
  // Set by another thread, it ends the run as interrupted at its next right-hand side (as a stop
  // request does, stop_request.hpp, for this run alone); nullptr: none.
  const std::atomic<bool>* cancel = nullptr;
  // Called on the run's thread as each phase after the first begins (auto's relinearizations and
  // hand-overs, as TransientResult::phases records them), before it integrates: what the run
  // has become is known then rather than at its end. Empty: none.
  std::function<void(const MethodPhase&)> phase_started;

  // Whether the options can run (t_end and output_step positive and finite, at most 1e8 output
  // steps, the integrator's options valid): true, or false with the first problem in *error.
  bool IsValid(std::string* error) const;
};

// Energies at one output time [J].
struct TransientSample {
  double t = 0.0;
  double kinetic = 0.0, elastic = 0.0, gravity = 0.0;
  double energy() const { return kinetic + elastic + gravity; }
};

struct SolverStats {
  double wall_seconds = 0.0;
  long steps = 0;
  long rhs_evaluations = 0;  // including those for finite-difference Jacobians
  long jacobian_evaluations = 0;
  long nonlinear_iterations = 0;
  long nonlinear_failures = 0;
  long error_test_failures = 0;
};

struct TransientResult {
  bool ok = false;
  bool timed_out = false;      // stopped by max_seconds
  bool interrupted = false;    // stopped by a stop request (stop_request.hpp)
  bool out_of_range = false;   // stopped where an element left its law's range (message: which)
  std::string linear_solver;   // dense | sparse | none
  long jacobian_nonzeros = 0;  // stored entries of the sparse Jacobian
  std::string message;         // why it stopped early, when !ok
  double t_reached = 0.0;      // last time integrated to [s]
  SolverStats stats;
  std::vector<std::string> warnings;
  // The phases of the run (auto: the first kMaxRecordedPhases, then the last), and how many there
  // were in all.
  std::vector<MethodPhase> phases;
  long phase_count = 0;
  // The band a modal phase integrated [Hz] (Integrator::band_hz): given, or chosen for rtol; 0:
  // every mode.
  double max_frequency_hz = 0.0;
  // The check of the elements' own axial forces (core/analysis/axial_force_watch.hpp): the
  // largest relative change of the deformation it measured, when [s], and over how many states
  // (0: none needed measuring).
  double axial_force_effect = 0.0;
  double axial_force_time = 0.0;
  int axial_force_states = 0;
  int axial_force_unmeasured = 0;    // states whose tangent could not be factorized
  double axial_force_seconds = 0.0;  // what the check cost
};
inline constexpr size_t kMaxRecordedPhases = 20;

using TransientObserver = std::function<void(const TransientSample&, const Data&)>;

// The highest frequency of the scene's harmonic loads and drives that scale something (a
// non-zero vector) [Hz]; 0 without one. No step of a transient is longer than 1 / (2 pi f)
// (transient.cpp), and the modal method's steps stay shorter still (modal_integrator.cpp).
double highest_harmonic_hz(const Model& model);

// Runs the analysis; observer sees t = 0 and every output step (data holds that state). Never
// throws: failures (solver, non-finite forces, observer errors) come back in the result, after the
// samples reached so far were delivered.
TransientResult run_transient(const Model& model, const TransientOptions& options, Data& data,
                              const TransientObserver& observer);

}  // namespace beamrail
