// The "auto" method of the transient analysis: it chooses per scene and per phase of the run.
//
// - At the start, the modal exponential integrator (core/analysis/modal_integrator.hpp)
//   linearized about the equilibrium under the loads at t = 0 (or the initial state), unless
//   damping that couples its modes damps beyond kAutoMaxDampingRatio of the fastest mode's
//   critical damping (each mode's own damping is exact in the modal method, the coupling
//   explicit): then dirk (the default table). From kAutoChosenBandDofs on, the modal method's band
//   is chosen for rtol (core/analysis/modal_band.hpp); when no band of the modes it may ask for
//   meets rtol, every mode up to kModalIntegratorMaxDofs, else bdf.
// - When a body turns more than kAutoRelinearizeRotation (less after cheap relinearizations,
//   below) from the orientation it is linearized about, the modal method is linearized again about
//   the current state (one eigenproblem) and the run goes on; when that happens more often than
//   every kAutoMinStepsPerLinearization steps (a body spinning fast: relinearizing costs more than
//   it saves), the rest of the run is integrated by dirk (ESDIRK547L2SA2_7_4_5, L-stable: it damps
//   the fast modes it does not resolve). A mechanism, or a part followed in a turning frame,
//   whose modal steps already resolve its fastest mode goes on with erk instead
//   (kAutoExplicitResolved). In a part of the scene that floats and spins the rotation counts
//   from a reference turning with that part (core/analysis/modal_coordinates.hpp). A damped
//   grounded mechanism (damping, a body not held by beams, no floating part) runs dirk from the
//   start (no energy check backs relinearized modal phases there, and bdf's higher orders are
//   unstable for its barely damped fast modes; auto_integrator.cpp).
//
// - A band it chose itself (for rtol) is widened when the inertia of the modes it keeps
//   quasi-static (their motion at second order: core/analysis/modal_integrator.hpp,
//   QuasiStaticInertia) is estimated to move the run by kAutoInertiaShare of what rtol leaves:
//   from that step on, every mode (up to kModalDenseBandMaxDofs) or a band kAutoBandWidening
//   times wider, linearized about that state. A band given in max_frequency_hz is the user's
//   model: it is kept, and the run warns instead.
//
// Every change is a MethodPhase of the result with its reason.
#pragma once

#include <memory>
#include <string>

#include "core/analysis/integrators.hpp"

namespace beamrail {

// The rotation from the linearization at which auto relinearizes the modal method [rad].
inline constexpr double kAutoRelinearizeRotation = 0.5;
// The rotation limit halves after a linearization whose steps outnumbered the degrees of
// freedom by more than 1 / this (relinearizing, ~n^3, is then cheap against the steps, ~n^2
// each), down to kAutoMinRelinearizeRotation.
inline constexpr double kAutoRelinearizeCostRatio = 0.03;
inline constexpr double kAutoMinRelinearizeRotation = 0.02;
// The first rotation limit is kAutoRelinearizeRotation from this many degrees of freedom on (100
// bodies), proportionally less below, down to kAutoMinRelinearizeRotation.
inline constexpr double kAutoFullRotationDofs = 600.0;
// Fewer modal steps than this between two linearizations, three times running: auto goes back
// to kAutoRelinearizeRotation (no lower than twice the limit that ran short), and at that limit
// goes on with the implicit method.
inline constexpr long kAutoMinStepsPerLinearization = 10;
// The implicit method auto falls back to mid-run.
inline constexpr const char* kAutoImplicitTable = "ESDIRK547L2SA2_7_4_5";
// Damping: the modal method integrates each mode's own damping exactly (modal_damping,
// core/analysis/modal_integrator.hpp) and the damping that couples the modes (members damped
// differently) explicitly, so that coupling d [1/s] holds its steps below about 2.5 / d; an
// L-stable implicit method steps over the damped fast modes once they have decayed. auto takes
// dirk (the default table) when d / (2 w_max) exceeds this, at the start or where a
// relinearization finds it so. Measured while all damping was explicit (scripts in the
// commit message of 2026-11): on the reference cantilever in 10 segments at rtol 1e-6,
// modal/bdf wall 0.16 at a ratio of 0.01, 0.41 at 0.05, 2.6 at 0.21, 9.3 at 0.83. With each
// mode's own damping exact, one `damping` for every member keeps the modal method at any
// strength: there bdf was 8 to 161 rtol off on the lightly damped cantilevers of an adversarial
// review (2026-11-29), the modal method within 1 rtol (docs/transient_measurements.md "Damped modes
// exact"). Until 2026-12-03 that method was bdf, which an adversarial review found slower and
// off where members are damped differently or a relinearized phase damps more (docs/
// transient_measurements.md "Damping that couples the modes goes on with dirk"): a portal frame
// with one column undamped, rtol 1e-4 / 1e-6 (against dirk at rtol 1e-10, in rtol): bdf 52,693 /
// 55,138 steps, 2.76 / 2.82 s, 0.0016 / 0.014; dirk 994 / 3,241 steps, 0.36 / 1.03 s, 0.0033 /
// 0.018. A damped cantilever bending 30 % under its tip load, handed over at 0.098 s: bdf from
// there 2.0 / 2.6 rtol off; bdf alone 6.8 / 45, dirk alone 0.0011 / 0.00035.
inline constexpr double kAutoMaxDampingRatio = 0.1;

// A modal phase (every mode integrated) that moved a mechanism (a body not held by beams and
// fixed joints to the ground) or a part followed in a turning frame, with steps its error
// estimates held below this share of the bound on w_max h there (kMechanismStep, kTurningFrameStep
// in core/analysis/modal_step_bounds.hpp; the smaller when both apply), goes on with erk
// kAutoExplicitTable from the end of that phase: its steps already resolve the fastest mode, so
// an explicit method's stability does not hold it shorter, and along such large motions the
// modal method's estimates were measured to miss its error where the explicit method's did not.
// On two adversarial reviews' 34 grounded mechanisms (2026-11-29; 2 s or 0.5 s, rtol 1e-4 / 1e-6
// / 1e-8, the centres against Verner 8(7) at rtol 1e-11, in rtol): a top on a spherical joint
// spinning at 30 rad/s (w_max 1.9e4 rad/s; its phases at 0.41 / 0.24 / 0.27 of the bound) 10 /
// 54 / 62 with the modal method, 0.013 / 0.017 / 0.030 with Verner (2 to 2.5 times the steps;
// Dormand-Prince 5(4) 0.12 / 0.19 / 0.24 in more); a pendulum on a spherical joint 0.61 / 4.2 /
// 0.86, then 0.86 / 0.008 / 0.002; a chain of three on spherical joints 0.54 / 1.2 / 0.69, then
// 0.38 / 0.0012 / 0.0009. The others' phases were at 0.54 to 1 of the bound and keep the modal
// method: where the bound holds a pendulum's steps erk resolves its stiff ringing itself, and
// Dormand-Prince took 4 times their steps at rtol 1e-8 (a hinged arm, w_max 9.9e4 rad/s: 1.4
// million against 346k, 0.03 and 0.25 rtol) and ran out of max_steps on a joint of compliance
// 1e-6. With every mechanism's phase under w_max h = 1.5 going on with Dormand-Prince, a double
// pendulum came out 21.5 rtol off at rtol 1e-6 (the modal method 6.8). Floating: the tumbling
// pair of tests/benchmarks/transient_auto, 10 s, 0.066 / 0.059 / 0.044 rtol at rtol 1e-6 / 1e-8
// / 1e-10 in 0.51 / 0.99 / 1.98 s (the modal method 0.88 / 1.2 / 1.6 rtol in 0.49 / 1.1 / 3.8 s;
// bdf 1.7 / 15 / 37 rtol in 0.58 / 1.9 / 3.7 s); a pair on a 20 mm rod spinning at 300 rad/s, 1
// s, 4.3 / 25 / 29 rtol at rtol 1e-4 / 1e-6 / 1e-8, then 2.1 / 8.2 / 3.8.
inline constexpr double kAutoExplicitResolved = 0.45;
// A modal phase of a mechanism whose steps the mechanism's bounds held below kMechanismHeldShare
// of the estimates' step (core/analysis/modal_step_bounds.hpp) this many times in its latest
// stretch of steps held at least kMechanismHeldStretch (modal_held_steps), goes on with dirk (the
// default table) from there: the ringing of stiff modes that the motion barely feels (a joint's
// penalty, a segment's torsion) then sets the modal steps, and an L-stable method steps over it. A
// 0.5 m steel rod of 10 mm in 100 segments with a 0.5 kg tip, on a revolute joint through a 0.1 kg
// hub, released level under gravity (0.3 s, rtol 1e-6): auto held every modal step from 0.02 s on
// at 5.9e-7 s (the 100-times floor, the estimates asking for 5.3e-5 s) and took 414 s in 536,232
// steps; dirk alone 34.5 s in 31,007 (docs/transient_measurements.md "Mechanisms held by their
// stiff ringing"). Only where those steps are work: held steps times the degrees of freedom squared
// (a modal step's products) at least kAutoHeldWork, about a second of them; a small scene's held
// steps are cheap, and an implicit method's are not (the stiff-hinge pendulum of
// tests/support/scenes.hpp: its modal steps are not held, 608,454 in 1.9 s; ESDIRK547 took 38.6 s).
inline constexpr long kAutoHeldSteps = 2000;
inline constexpr double kAutoHeldWork = 5e8;
// The explicit method auto hands over to (kAutoExplicitResolved).
inline constexpr const char* kAutoExplicitTable = "VERNER_8_5_6";

// From this many degrees of freedom on, auto chooses the modal method's band for rtol
// (IntegratorOptions::choose_band) unless one is given: the modes whose ringing the run can show
// at rtol, the others quasi-static (per step ~ bodies x modes instead of bodies^2). At 600 (a
// 100-segment cantilever, rtol 1e-6) the chosen band (77 modes) ran in 1.2 s, every mode in 1.8 s.
inline constexpr int kAutoChosenBandDofs = 600;

// A chosen band's phase ends when its quasi-static inertia's drift passes this share of what is
// left of rtol (rtol less the drift of the phases before): the drift already run stays in the
// result, so the run's sum stays below rtol.
inline constexpr double kAutoInertiaShare = 0.5;
// Above kModalDenseBandMaxDofs, the band's top frequency is multiplied by this.
inline constexpr double kAutoBandWidening = 4.0;

// The auto integrator for the system in `context`, starting at (0, y0).
std::unique_ptr<Integrator> make_auto_integrator(const IntegratorOptions& options,
                                                 OdeContext& context, SUNContext sunctx,
                                                 N_Vector y0, std::string* error);

}  // namespace beamrail
