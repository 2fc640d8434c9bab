// The "modal" integrator: an exponential Runge-Kutta method in the modal basis of one
// linearization, for small motions about one configuration (vibration of stiff structures). The
// configuration (c0, A0 per free body) is the static equilibrium under the loads at t = 0 or the
// initial state (IntegratorOptions::about).
//
// Generalized coordinates per free body: x = (dc, theta) with c = c0 + dc and A = exp([theta]x) A0
// (global rotation vector), velocities u = dx/dt = (v, dtheta/dt); the angular velocity is
// omega = J(theta) dtheta/dt (left Jacobian of SO(3), core/model/rotation.hpp), so that dx/dt = u
// holds exactly and every nonlinearity is in the accelerations. With the mass matrix M0 and the
// symmetric part K0 of the tangent stiffness at (c0, A0), at rest (theta = 0, where J = I), and
// the M0-normalized modes Phi (Phi^T K0 Phi = diag(lambda), Phi^T M0 Phi = I), x = Phi eta,
// u = Phi nu and
//   d eta / dt = nu,
//   d nu / dt  = -lambda eta - c nu + [Phi^T M0 a(x, u) + lambda eta + c nu],
// a being the exact accelerations (dv/dt, d^2 theta/dt^2) of the equations of motion and c each
// mode's own damping (phi^T M0 C phi, C = -da/du at the linearization; 0 without damping). Each
// mode's linear part [[0, 1], [-lambda, -c]] is integrated exactly (phi functions of 2 x 2
// blocks, core/analysis/exponential_step.hpp); the bracket (nonlinearity, load changes, damping
// between modes, the non-symmetric part) by the stiff-order-4 exponential Runge-Kutta method of
// Hochbruck and Ostermann (2005). Steps are controlled by the
// distance to an embedded third-order solution from the same stages, measured in the physical
// states; the fourth-order solution is kept (its error follows rtol: 0.01 .. 1.9 rtol measured,
// transient_auto_test.cpp).
//
// Cost: one dense eigenproblem (n_dofs^3) at set-up, then per stage one dense product with two
// columns (x, u = Phi (eta, nu); core/analysis/dense_product) and one transposed product with
// one (Phi^T (M0 a), M0 a 6 x 6 block per body: Phi is the one dense matrix stored, and a stored
// M0 Phi beside it made the braced tower's every-mode run 26 % slower per step); with every mode
// integrated, each stage's transposed product shares its pass over Phi with the next product
// (five passes a step); hence a size limit. The bodies' coordinates and the way back to the
// model's states: core/analysis/modal_coordinates.hpp.
// The products use the threads of the caller's budget (ProductThreads,
// core/analysis/dense_product.hpp): the tower's 1 s run took 14.3 s on 2 threads, 15.8 s on 1
// (AVX2 kernels; docs/transient_measurements.md "Why this machine ran the tower slower").
// Accuracy degrades with the size of the motion: past kMaxRotation the run stops with a message
// naming the body. A part of the scene that floats and spins is followed in a frame turning with it
// (core/analysis/modal_coordinates.hpp): its rigid spin is no motion away from the linearization
// there, and the steps stay below min(3, (rtol / 1e-8)^(1/4)) / w_max (kTurningFrameStep). A
// mechanism (a body not held by beams and fixed joints to the ground, in no floating part) turns
// its stiff directions as it moves: its steps stay below min(3, 0.6 (rtol / 1e-8)^(1/4)) / w_max
// (kMechanismStep) while its stiff modes hold energy, and never 100 times shorter than the
// estimates' step (kMechanismMostShorter). These bounds and their measurements:
// core/analysis/modal_step_bounds.hpp.
//
// Band-limited (IntegratorOptions::max_frequency_hz): only the m modes up to the band are
// integrated (from the dense eigensolver, or above kModalDenseBandMaxDofs from shift-invert
// Lanczos, core/analysis/modal_analysis.hpp); the others are quasi-static: x = Phi z + y, y
// M0-orthogonal to the modes kept and such that the accelerations have no part outside the band
// (y is the static response of the modes above the band to everything the linear part leaves
// out), found by the Newton iteration y <- y + R M0 a(Phi z + y), R = (K0 + mu M0)^-1 -
// Phi (Lambda + mu)^-1 Phi^T (the residual flexibility; mu = 1e-2 (2 pi max_frequency_hz)^2
// keeps rigid and mechanism modes, which lie in the band, from making it singular); one sparse
// LDL^T at set-up, usually one or two evaluations per stage. Their velocities are not followed.
// Cost per stage: products with n x m matrices and one sparse solve: bodies x modes.
// IntegratorOptions::choose_band picks the band for rtol (core/analysis/modal_band.hpp); the
// choice is the run's one phase (summary.json method_reason).
#pragma once

#include <array>
#include <memory>
#include <string>

#include "core/analysis/integrators.hpp"
#include "core/analysis/modal_reference.hpp"

namespace beamrail {

// Largest scene the modal integrator integrates every mode of [degrees of freedom = 6 per free
// body]: one dense eigenproblem at set-up (~n^3) and products with the n x n basis (~n^2 per
// stage); above it only a band (max_frequency_hz). Measured where auto takes it because no band
// meets rtol: docs/transient_measurements.md "Every mode where no band meets rtol".
inline constexpr int kModalIntegratorMaxDofs = 2400;
// Up to this many degrees of freedom a band's modes come from the dense eigensolver, above from
// shift-invert Lanczos (core/analysis/modal_band.hpp).
inline constexpr int kModalDenseBandMaxDofs = 1200;
// Most modes a chosen band (IntegratorOptions::choose_band) asks the sparse eigensolver for; when
// none meets rtol, up to kModalIntegratorMaxDofs the dense eigensolver gives every mode.
inline constexpr int kModalChosenBandMaxModes = 400;
// Largest rotation of a body from the orientation it is linearized about that the method follows
// [rad].
inline constexpr double kModalIntegratorMaxRotation = 1.0;

// The flag of a run stopped because a body turned more than the rotation limit from the
// orientation it is linearized about (y and t then hold the last accepted state).
inline constexpr int kModalTooFar = -20;
// The flags of a run stopped because its step fell below the roundoff of the time, and because
// the forces of a trial state were not finite ten times running (y and t: the last accepted
// state).
inline constexpr int kModalStepTooSmall = -3;
inline constexpr int kModalNonFinite = -8;
// The flag of a band-limited run stopped because the inertia its quasi-static modes leave out
// passed the limit of set_modal_inertia_limit (y and t: the step's accepted state where it did).
inline constexpr int kModalInertia = -21;
// The flag of a run stopped because its trial states left the range of an element's law (a
// carriage past its rail's travel, a beam bent past its angle limit) kNonFiniteLimit times within
// one call, or because the step fell below the roundoff of the time while they did: the element
// left its law where the run stopped (y and t: the last accepted state, inside the range).
inline constexpr int kModalOutOfRange = -22;
// The flag of a mechanism's run stopped because the held steps of its latest stretch
// (modal_held_steps) reached the limit of set_modal_held_limit (y and t: the step's accepted
// state where they did).
inline constexpr int kModalHeld = -23;

// The angular velocity of the fastest frame in which a modal integrator follows a floating part
// of the scene that spins (core/analysis/modal_coordinates.hpp) [rad/s]; 0 in fixed axes or for
// another integrator.
double modal_frame_rate(const Integrator& integrator);
// The eigenvalues w^2 of a modal integrator's linearization: the smallest positive one and the
// largest [1/s^2]. False when `integrator` is not a modal integrator.
bool modal_spectrum(const Integrator& integrator, double* smallest_positive, double* largest);

// A modal integrator's damping [1/s]: the largest of its modes' own (c_i = phi_i^T M0 C phi_i,
// C the damping matrix at the linearization; integrated exactly with each mode) and the
// largest coupling it leaves to the explicit remainder (per mode, the norm of C phi_i - c_i
// phi_i in M0's inverse); both 0 without damping. False when `integrator` is not modal.
bool modal_damping(const Integrator& integrator, double* largest, double* coupling);

// How a modal integrator chose its band ("band 812 Hz: 40 of 5,994 modes, ..."); "" when it was
// given or the integrator is not modal.
std::string modal_band_choice(const Integrator& integrator);
// Why a modal integrator linearized about the initial state though "about" did not ask for it
// (no static equilibrium that can serve: modal_reference).
InitialLinearization modal_initial_linearization(const Integrator& integrator);

// What a band-limited modal run drops with the kinetic energy of the modes it keeps
// quasi-static (core/analysis/quasi_static_modes.hpp).
struct QuasiStaticInertia {
  double band_hz = 0.0;  // the band's top [Hz]
  double ratio = 0.0;    // their largest kinetic energy over the band's largest
  double drift = 0.0;    // the error that leaves, estimated, relative to the motion
  double t = 0.0;        // up to this time [s]
};
// Of a modal integrator's run so far; false when it is not a band-limited modal integrator.
bool modal_quasi_static_inertia(const Integrator& integrator, QuasiStaticInertia* out);
// The run's warning for a drift above rtol.
std::string quasi_static_inertia_warning(const QuasiStaticInertia& inertia);
// Makes a band-limited modal integrator stop (kModalInertia) after the step at which its
// QuasiStaticInertia drift first passes `drift` (0: never, the default), so that its caller can
// go on with more modes; false when `integrator` is not a band-limited modal integrator.
bool set_modal_inertia_limit(Integrator& integrator, double drift);
// That check waits until the band's slowest elastic mode has turned far enough since t (before
// the integrator's own start: a band relinearized, whose phases are each too short to settle);
// false when `integrator` is not a band-limited modal one.
bool set_modal_settling_start(Integrator& integrator, double t);

// The step size a modal integrator would try next [s]; 0 when `integrator` is not one.
double modal_step_size(const Integrator& integrator);
// The latest stretch of accepted steps in which a mechanism's bounds held at least
// kMechanismHeldStretch of them below kMechanismHeldShare of the step the error estimates and the
// other limits asked for (core/analysis/modal_step_bounds.hpp): its steps and the held ones.
struct HeldSteps {
  long held = 0;
  long steps = 0;
};
// That stretch of `integrator`'s steps; none when it is not a modal integrator.
HeldSteps modal_held_steps(const Integrator& integrator);
// Makes a modal integrator stop (kModalHeld) after the step at which the held steps of its latest
// stretch reach `held` (0: never, the default); false when `integrator` is not a modal
// integrator.
bool set_modal_held_limit(Integrator& integrator, long held);
// Continues `from`'s latest stretch of held steps in `to` (a phase relinearized from it): a
// mechanism relinearized every few thousand steps counts its held steps across its phases.
void continue_modal_held_steps(const Integrator& from, Integrator& to);

// Whether a modal integrator's mechanism step bound (kMechanismStep) holds at its accepted state:
// a mechanism whose stiff modes hold energy.
bool modal_mechanism_bound(const Integrator& integrator);
// Makes a modal integrator hold its mechanism step bound from the start, whatever its stiff
// modes hold: a phase relinearized where the bound held begins with its stiff modes holding
// almost nothing in the new linearization, and long first steps there count.
void hold_modal_mechanism_bound(Integrator& integrator);

// The modal integrator for the system in `context`, starting at (t0, y0); the loads are those of
// t0 in the linearization.
std::unique_ptr<Integrator> make_modal_integrator(const IntegratorOptions& options,
                                                  OdeContext& context, N_Vector y0,
                                                  std::string* error, double t0 = 0.0);

}  // namespace beamrail
