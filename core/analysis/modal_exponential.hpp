// The modal exponential integrator's class (core/analysis/modal_integrator.hpp is its interface):
// set up in core/analysis/modal_basis.cpp (the linearization, the modes, a band, their damping),
// stepped in core/analysis/modal_integrator.cpp, its band's quasi-static part iterated in
// core/analysis/modal_quasi_static.cpp. Internal to those three files.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <numbers>

#include "core/analysis/deformation_check.hpp"
#include "core/analysis/dense_product.hpp"
#include "core/analysis/explicit_stability.hpp"
#include "core/analysis/exponential_step.hpp"
#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/modal_band.hpp"
#include "core/analysis/modal_coordinates.hpp"
#include "core/analysis/modal_integrator.hpp"
#include "core/analysis/modal_reference.hpp"
#include "core/analysis/modal_step_bounds.hpp"
#include "core/analysis/quasi_static_modes.hpp"
#include "core/analysis/static_analysis.hpp"
#include "core/analysis/transient.hpp"
#include "core/model/dynamics.hpp"
#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"
#include "core/model/rotation.hpp"

namespace beamrail::modal_detail {

constexpr int kD = kDofsPerBody;

using Block = ModeBlock;

// out = a b (a change of basis of both columns; a is n x n, or a band's n x m basis or its
// transpose).
inline void multiply(const Eigen::MatrixXd& a, const Block& b, Block& out) {
  out.resize(a.rows(), 2);
  multiply_pair(a, b.data(), out.data());
}

// set_inertia_limit applies from this angle of the band's slowest elastic mode on [rad].
constexpr double kInertiaSettling = 2.0;

enum Flag {
  kOk = 0,
  kTooManySteps = -1,
  kStepTooSmall = kModalStepTooSmall,
  kNonFinite = kModalNonFinite,
  kTooFar = kModalTooFar,
  kInertia = kModalInertia,
  kOutOfRange = kModalOutOfRange,
  kHeld = kModalHeld
};

class ModalExponential : public Integrator {
 public:
  bool init(const IntegratorOptions& o, OdeContext& c, N_Vector y0, std::string* error, double t0);

  int advance(double tout, double tstop, N_Vector y, double* t) override;

  void restart(double t, N_Vector y) override;

  SolverStats stats() const override { return stats_; }

  std::vector<MethodPhase> phases(long* count) const override {
    *count = band_estimate_ >= 0.0 ? 1 : 0;
    if (!*count) return {};
    return {MethodPhase{t0_, "modal", band_choice()}};
  }

  const InitialLinearization& initial_linearization() const { return initial_; }

  std::string band_choice() const;

  const Eigen::ArrayXd& eigenvalues() const { return blocks_.lambda; }
  const Eigen::ArrayXd& damping() const { return blocks_.damping; }
  double damping_coupling() const { return damping_coupling_; }
  double step_size() const { return h_; }
  HeldSteps held_steps() const { return held_; }

  // The largest rotation of a body from the linearization at the accepted state [rad].
  double largest_rotation() const { return coordinates_.largest_rotation(x_); }

  // Whether the mechanism's step bound holds at the accepted state (z: the modes there, z_ or
  // with their ringing about the static state of the forces: ringing_about_static_state).
  bool mechanism_bound(const ModeBlock& z) const {
    return bounds_.mechanism > 0.0 &&
           (bounds_.hold_mechanism || modal_stiff_share(blocks_.lambda, z) > kMechanismStiffShare);
  }
  bool mechanism_bound() const { return mechanism_bound(z_); }
  void hold_mechanism_bound() { bounds_.hold_mechanism = true; }

  // The modes at the accepted state with their ringing about the static state of the forces
  // there (ringing_about_static_state), once the step's start has been evaluated: the
  // band-limited iteration left Phi^T M0 a in psi_a_; else M0 a is in m0_v_ (one more pass).
  const ModeBlock& start_ringing();

  // The longest step, at most `h`, from the accepted state that no element crosses an edge of
  // its range or of its warnings unseen: the modes that could carry it there resolved
  // (kResolvedPhase / modal_edge_rate), the paths of the slow and rigid modes bounded
  // (modal_slow_edge_step). Either N at that state is in n0_, or (every mode integrated) M0 a is
  // in m0_v_ and a in acceleration_: there the modal accelerations cost a pass over Phi, taken
  // only when a bound on them (|psi_a_i| <= |a|_M0, the modes mass-normalized) does not already
  // rule the edges out (the braced tower: never).
  double edge_step(double h);

  // The frequency of the mechanism's ringing modes at the accepted state [rad/s] (0: none).
  double ringing_rate(const ModeBlock& z) const {
    if (!(bounds_.mechanism_wh > 0.0)) return 0.0;
    return modal_ringing_rate(blocks_.lambda, order_, z, kMechanismRingingShare);
  }

  std::string failure(int flag) const override;

 private:
  bool fail(std::string* error, const std::string& what) {
    *error = what;
    return false;
  }

  // The modes of the band (dense eigensolver up to kModalDenseBandMaxDofs, else shift-invert
  // Lanczos asked for more modes until one lies above the band or, when the band is chosen
  // (options_.choose_band, core/analysis/modal_band.hpp), until the band meets rtol) and, when
  // some lie above, the factored K0 of the static correction. The linearization is posed in
  // `data`; y0 is the initial state.
  bool band_limited_basis(const Model& model, Data& data, double t0, const double* y0,
                          std::string* error);

  // The modes' damping c_i = phi_i^T M0 C phi_i (C = -da/du at the linearization, from central
  // differences of the accelerations in the velocity phi_i: the forces linear in the velocities
  // exactly, the gyroscopic ones, quadratic, cancelled) into blocks_.damping, integrated exactly
  // with each mode's block; the rest of C (its coupling between modes) stays in N. Its size,
  // |C phi_i - c_i phi_i| in M0's inverse (with every mode: the norm of the column of Phi^T M0 C
  // Phi off its diagonal), largest over the modes, into damping_coupling_. False when the
  // forces are not finite.
  bool modal_damping(double t0);

  // out = Psi^T v = Phi^T (M0 v), the modal part of the physical vector v (M0 is a 6 x 6 block
  // per body; Phi alone is stored and read, so that each stage's passes share one n x m matrix).
  void project(const Eigen::Ref<const Eigen::VectorXd>& v, double* out) {
    m0_v_.noalias() = m0_ * v;
    multiply_transposed(phi_, m0_v_.data(), out);
  }

  // One Newton correction of the quasi-static part: y += R M0 a, with Psi^T a given (psi_a);
  // returns its size in weights of the motion, rtol x + atol, x the largest offset from the
  // linearization (of the translations for theirs, of the rotations for theirs): the tolerance
  // a run's error is measured against (verify, work-precision studies). Not the step's weights,
  // rtol |c| + atol of the centres c: those depend on where the scene sits, and what is left of
  // y acts through the stiffness of the modes above the band. A 1 kg bob 0.3 m below a revolute
  // joint of relative compliance 1e-9, in a band of 20 Hz at rtol 1e-4, atol 1e-9, under a 1e-3
  // N m torque at 2 Hz for 1 s, came out 611 times rtol x + atol off its closed form with the
  // step's weights (3e-5 m across the swing: y stopped within 3e-10 m of a joint of 6e12 N/m),
  // and 0.04 times with the bob at the origin and the joint above it (tests/core/analysis/
  // transient_auto_band_test.cpp, TransientBand). What it costs: docs/transient_measurements.md "A
  // band's quasi-static part, wherever the scene sits". Weights of each offset, rtol |x_i| + atol,
  // are tighter still where an offset is small (along a chain's stiff axis) and took the
  // 1,000-segment cantilever 115 s (these 107 s, the step's weights 73 s) for the same error; these
  // weights with the iteration stopped at 1e-3 of them (kQuasiStaticTolerance) 84 s, but the bob 11
  // to 86 times off.
  double correct(const Eigen::VectorXd& psi_a, Block& x);

  // The quasi-static iteration's matrix from the tangent at time t and the physical state x
  // whose 13 states are in y13_: the rotation of stiff members with the motion makes K0 a poor
  // Newton matrix for the modes above the band (a stiff axial mode turned by the bending), and
  // the iteration slows or diverges. One sparse LU factorization and m solves.
  bool update_tangent(double t, const Block& x);

  // z from the 13 states of every free body.
  void from_states(const double* y);

  // Physical coordinates x = Phi z into the 13 states; false (with far_body_ set) when a body
  // turned too far.
  bool states_of(double t, const Block& x, double* y) {
    return coordinates_.states(t, x, y, max_rotation_, &far_body_);
  }

  // The accepted state (a rotation past the limit is reported by the next step that uses it),
  // with the quasi-static part's rate in the velocities when known.
  void to_states(double* y);

  // The accelerations (dv/dt, d^2 theta/dt^2) into acceleration_ at the physical state x whose
  // 13 states states_of has just written into y13_; false when they are not finite.
  bool accelerations(double t, const Block& x);

  // N(t, z) of a band-limited run: everything but the modes' linear part, in modal coordinates,
  // with the quasi-static part iterated into x (x = Phi z + y is given). Every mode integrated,
  // step() projects N in its passes instead. False when the forces are not finite or a body
  // turned too far.
  bool nonlinear(double t, const Block& z, Block& x, Block& out, int* flag);

  // nonlinear() at the accepted state (t_, z_, x_) into n0_; where it fails (or throws) x_ is
  // what it was before: the iteration's diverged quasi-static part is not the state a method
  // going on from here starts from, nor the state reported.
  bool nonlinear_at_accepted(int* flag);

  // The quasi-static part's second-order pull at the start (QuasiStaticModes::set_pull): its
  // change when the band moves from the accepted state to its static response there, against
  // that motion (the kinetic energy it would carry against the band's). The linear estimate of
  // the band (modal_band.hpp) leaves it out, and the run's own check waits until it has settled
  // (kInertiaSettling): a 1 kg tip on a 10-segment cantilever under a 300 N step, auto's bands
  // relinearized every 5 to 40 ms, dropped 0.19 of the kinetic energy (the tip pulled in along the
  // stiff axis as it swings) and the run ended 0.056 of the motion off, widened at 0.088 s; here
  // the ratio is measured before the first step. Unchanged where the iteration does not reach the
  // target (its check during the run stays). Evaluates the accepted state again after; false
  // (*flag set) when that fails.
  bool measure_pull(int* flag);

  // Whether the quasi-static part's change over the step just accepted stands above the
  // iteration's noise (kQuasiStaticNoiseMargin): its kinetic energy then counts.
  bool quasi_step_resolved() const;

  // The accelerations at the physical state x and M0 a into m0_v_, for a projection that
  // finishes N (every mode integrated: N = Phi^T M0 a + lambda z, project_then). False when the
  // forces are not finite or a body turned too far.
  bool evaluate(double t, const Block& x, int* flag);

  // One trial step of size f.h from the accepted state (t_, z_): the new state into next_, and
  // with its two error distances into trial_ (modal) and trial_x_ (physical). N(t_, z_) is n0_
  // when have_n0_; else its accelerations are in m0_v_ (evaluate). Every mode integrated, each
  // stage's forcing is projected in the pass over Phi that makes the next stage's physical state
  // (or the new state and its distances): multiply_transposed_then, one pass for two products
  // and the same bits. Band-limited, the quasi-static iteration projects it on its own.
  bool step(const StepFunctions& f, int* flag);

  // The pass over Phi that projects stage `stage - 1`'s forcing (M0 a in m0_v_) and multiplies
  // x (m x vectors, written on the way by fill with the step's functions f) into y.
  void project_then(const StepFunctions& f, int stage, double* x, int vectors, double* y);

  static void fill_rows(void* self, long begin, long end) {
    static_cast<ModalExponential*>(self)->fill(begin, end - begin);
  }

  // The `count` modes from `begin` of the projected stage's N (Phi^T M0 a, written by the pass,
  // + lambda z), then of what the pass multiplies: stage fill_stage_'s state, or at the step's
  // end the new state and its distances.
  void fill(Eigen::Index begin, Eigen::Index count);

  // The `count` modes from `begin` of the new state's two error distances (next_ holds the new
  // state), and the three side by side into trial_: the distance to the embedded third-order
  // solution, h b5 (N5 - N3), and to the embedded second-order one from stages 1 and 2.
  void estimates(const StepFunctions& f, Eigen::Index begin, Eigen::Index count);

  // Weighted RMS norm of an error e = Phi dz in the physical states (x: rtol |c| + atol for
  // positions, rtol + atol for rotations; u: rtol |u| + atol) at the physical state x.
  double error_norm(const Eigen::Ref<const Block>& e, const Block& x);

  // The error estimate: the distance to the embedded third-order solution, O(h^4), over
  // kToleranceScale, and the distance to the embedded second-order one, O(h^3), over
  // kLowOrderScale rtol^(3/4): both ask for steps ~ rtol^(1/4), so the achieved error of the
  // fourth-order solution kept follows rtol. The third-order estimate alone compares two
  // evaluations at the same time (c = 1/2) and misses forcing that varies fast within a step: a
  // step torque that sets a 6-segment cantilever's torsion (5.6e5 rad/s) beating against its
  // bending gave 6 .. 290 rtol with it alone (the previous engineer's note, not re-measured); the
  // second-order one sees that. Measured against tight explicit runs over rtol 1e-4 .. 1e-9
  // (transient_auto_test.cpp, ErrorFollowsTheTolerance, auto): 0.011 .. 0.060 rtol on the
  // reference cantilever in 10 segments, 0.017 .. 1.3 on that torsion case, 0.13 .. 1.9 on the
  // tumbling pair (relinearized, in fixed axes: since followed in a turning frame, 0.02 .. 0.13);
  // the second-order estimate alone gave 1e-2 .. 1e-5 rtol there.
  // Where it costs: the braced tower of docs/transient_measurements.md (1,038 dof, 2 kN step,
  // rtol 1e-6, atol 1e-9, 0.2 s) takes 797 steps held by the second-order estimate, almost all of
  // it in the angular velocities (atol-weighted: they are near zero), and leaves 0.03 rtol. The
  // forcing there is the deflection times the fast modes (its steps follow the band's top: 246,
  // 613, 786 and 797 steps for bands of 300 Hz, 1 kHz, 3 kHz and every mode). Tried and rejected,
  // measured with ErrorFollowsTheTolerance: the second-order estimate at 0.1 of its weight (tower
  // 298 steps, 0.4 rtol) leaves 20 rtol on the step-torque case at rtol 1e-5; on positions only, or
  // the third-order one alone (185 steps, 2.6 rtol), 16 .. 476 rtol there; from stages 1 and 4
  // (exponential trapezoid) instead of 1 and 2, 741 steps; weights rtol |omega| + atol per body:
  // 445 steps, 14 .. 99 rtol there (small bending rates beside the torsion set the deflection).
  static constexpr double kExponent = 0.25;
  // The quasi-static iteration stops when its correction is below this part of the error
  // weights: what is left of it enters the forcing through the stiffness of the modes above the
  // band, and the step control sees it as error. Measured on the reference cantilever in 10
  // segments, rtol 1e-7, 0.1 s (TransientBand): at 0.05, bands 500 and 2000 Hz took 1,630 and
  // 2,596 steps (the full model 1,407); at 1e-2, 126 and 2,598; at 1e-3, 100 (one per output)
  // and 437, with 1,071 and 4,825 evaluations; at 1e-5, 100 and 441 with 1,369 and 6,580. On a
  // bending chain the rest of the iteration is what holds the steps: the 1,000-segment cantilever
  // under 1 N over 60 ms took 4,106 steps and 20,966 evaluations at 1e-3, 1,916 and 13,718 at
  // 1e-5, 1,348 and 18,180 at 1e-7 (1,349 and 27,525 at 1e-9); the 201-segment one over 10 ms
  // left 3.0 and 2.9 rtol at 1e-3 against an independent run, 0.54 and 0.71 rtol at 1e-5 (rtol
  // 1e-4, 1e-5; tests/core/analysis/transient_auto_band_test.cpp). (Those were measured in the
  // step's weights; the iteration now stops in the motion's, correct().)
  static constexpr double kQuasiStaticTolerance = 1e-5;
  // A step's change of the quasi-static part counts as its motion (QuasiStaticModes::accepted)
  // where it is more than this many times the largest last correction of the iteration since the
  // step before (its noise). The review's 100-segment cantilever under an 8 kN step
  // (docs/transient_measurements.md "Damping that couples the modes goes on with dirk") had its
  // largest |dy/dt|^2_M0 at a step of 1.2e-11 s, 6.7e9, where steps of 3e-6 s gave 1e-4 against
  // the band's 0.01 to 200, and its run warned of an error of 3e7 of the motion.
  static constexpr double kQuasiStaticNoiseMargin = 10.0;
  // The corrections of one evaluation of the band's forcing at most.
  static constexpr int kQuasiStaticIterations = 8;
  // The Newton matrix's updates within one evaluation at most (nonlinear()).
  static constexpr int kQuasiStaticUpdates = 3;
  // After an update, a correction more than this part of the one before takes the tangent
  // again where it is (a chord iteration gone stale; nonlinear()).
  static constexpr double kQuasiStaticSlowContraction = 0.5;
  // A floating part is followed in a turning frame when it turns more than this over the run
  // [rad].
  static constexpr double kTurningFrameMinTurn = 1e-3;
  static constexpr double kToleranceScale = 10.0;
  static constexpr double kLowOrderScale = 3.0;

  // Advances by one accepted step (or to `target`). Returns a flag.
  int step_towards(double target);

 public:
  QuasiStaticInertia quasi_static_inertia() const { return quasi_.inertia(band_hz_, t_, t_ - t0_); }

  // advance() stops (kInertia) after the step whose drift first passes `drift` (0: never), once
  // inertia_settled().
  void set_inertia_limit(double drift) { inertia_limit_ = drift; }

  // advance() stops (kHeld) after the step at which the held steps of the latest stretch reach
  // `held` (0: never).
  void set_held_limit(long held) { held_limit_ = held; }
  void continue_held_steps(const HeldSteps& stretch) { held_ = stretch; }

  // Whether the band's slowest elastic mode has turned kInertiaSettling rad since the run began.
  // Before, a load that starts from rest gives a ratio of kinetic energies far above the
  // motion's: the quasi-static part follows the load at once, the band only over about a third
  // of its period (the heavy tip's smooth ramp: 9e-5 at 5 ms, 1e-7 at 2 rad, 5e-8 from then on).
  // Counted from set_settling_start's time where given (a band relinearized: since the band's
  // first phase).
  bool inertia_settled() const {
    return quasi_.settled(t_ - std::min(t0_, settling_start_), kInertiaSettling);
  }
  void set_settling_start(double t) { settling_start_ = t; }

  bool band_limited() const { return reduced_; }

  std::vector<std::string> closing_warnings() const override;

 private:
  int fail_flag(int flag);

  // " (turning with its part of the scene at W rad/s)" for a body in a turning frame, else "".
  std::string turning_text(int body) const;

 public:
  // The angular velocity of the frame the run follows the scene in [rad/s]; 0 in fixed axes.
  double frame_rate() const { return coordinates_.fastest_frame_rate(); }

 private:
  IntegratorOptions options_;
  OdeContext* context_ = nullptr;
  Eigen::Index n_ = 0;  // degrees of freedom
  Eigen::Index m_ = 0;  // modes integrated (n_ unless band-limited)
  // Band-limited (m_ < n_): the modes above the band are quasi-static, x = Phi z + y
  // (core/analysis/quasi_static_modes.hpp).
  bool reduced_ = false;
  QuasiStaticModes quasi_;
  Eigen::SparseMatrix<double> m0_;
  Eigen::VectorXd m0_a_, psi_a_;  // work space: M0 a, Phi^T M0 a
  Eigen::ArrayXd edge_psi_a_;     // work space of edge_step: Phi^T M0 a at the accepted state
  Block n0_;                      // N at the accepted state, when have_n0_
  bool have_n0_ = false;
  bool starting_ = true;          // no step accepted since the start or the last restart
  ModeBlock start_ringing_;       // start_ringing()
  double band_hz_ = 0.0;          // the highest frequency integrated [Hz]
  double band_estimate_ = -1.0;   // a chosen band's estimated error (modal_band.hpp); -1: given
  InitialLinearization initial_;  // why the initial state was linearized about (modal_reference)
  Eigen::Index band_needed_ = 0;  // the modes the chosen band needed
  Eigen::MatrixXd phi_;           // x = Phi z, z = Psi^T x with Psi = M0 Phi (project)
  ElementReach reach_;            // how far each mode moves each element, in xi and angle
  Eigen::VectorXd m0_v_;          // work space of project
  ModeBlocks blocks_;  // the modes' linear part: eigenvalues and damping (exponential_step.hpp)
  double damping_coupling_ = 0.0;  // modal_damping: the damping left in N, per mode velocity
  ModalCoordinates coordinates_;   // the bodies' offsets from the linearization and back
  Block z_, x_;                    // the accepted state, modal and physical (x_ = Phi z_)
  Block accepted_x_;               // work space of nonlinear_at_accepted
  Eigen::VectorXd y_entry_;        // nonlinear(): the quasi-static part it began from
  // The largest last correction of the quasi-static iteration since the last accepted step, and
  // the weights of the latest correction (translations, rotations): correct().
  double qs_noise_ = 0.0;
  double qs_weights_[2] = {1.0, 1.0};
  Block xi_, x_next_;  // work space: a stage's physical state, a trial step's
  // A trial step's new state and its two error estimates side by side, modal and physical.
  Eigen::Matrix<double, Eigen::Dynamic, 6> trial_, trial_x_;
  // Work space: the modal states of the last two stages, a trial step's new state, its distances.
  Block stage_z_[2], next_, third_, second_;
  int fill_stage_ = 0;  // the stage (kStages: the new state) whose pass is under way, and
  const StepFunctions* fill_functions_ = nullptr;  // the functions of its step
  double inertia_limit_ = 0.0;                     // set_inertia_limit
  long held_limit_ = 0;                            // set_held_limit
  Eigen::VectorXd acceleration_;  // work space: the physical accelerations of a stage
  double t_ = 0.0, h_ = 0.0;
  double t0_ = 0.0;                                                  // where the run started
  double settling_start_ = std::numeric_limits<double>::infinity();  // set_settling_start
  double pull_ = -1.0;  // measure_pull's ratio; -1: not measured
  StepFunctions full_;
  Block stage_n_[StepFunctions::kStages];
  std::vector<double> y13_, ydot13_;
  std::vector<double> watched_;  // an accepted step's states, for OdeContext::step_taken
  SolverStats stats_;
  HeldSteps
      held_;  // the latest stretch of steps the mechanism's bounds held (kMechanismHeldStretch)
  int far_body_ = -1;
  std::string detail_;
  double max_rotation_ = kModalIntegratorMaxRotation;
  std::vector<Eigen::Index> order_;  // the modes from the fastest down
  ModalStepBounds bounds_;         // the longest steps beside the estimates (modal_step_bounds.hpp)
  double low_order_weight_ = 1.0;  // rtol^(1/4) / kLowOrderScale
};

}  // namespace beamrail::modal_detail
