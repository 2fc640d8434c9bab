// The modal method's step bounds beside its error estimates (core/analysis/modal_integrator.hpp):
// where the estimates were measured to miss an error on long steps, the steps stay below a bound.
// Each constant is fitted to the runs its comment names.
#pragma once

#include <vector>

#include "core/analysis/exponential_step.hpp"
#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// A floating scene that spins is followed in a frame that turns with it
// (core/analysis/modal_coordinates.hpp): its rigid spin then leaves no remainder, but the frame's
// Coriolis and gyroscopic accelerations couple every mode's velocity into the others through the
// remainder, and the error estimates do not see what that does on long steps: on a free pair
// on a steel rod (w_max 2.1e4 rad/s, the rod's axial mode) spinning at 8 rad/s, 3 s, at rtol
// 1e-10 (where the estimates hold the steps no more), the error of the centres went as
// (w_max h)^4 (1.6e-9, 7.5e-9, 4.0e-8, 2.1e-7 at w_max h = 1, 1.5, 2.25, 3.4), then jumped
// (9.9e-6 at 5; in fixed axes a resonance at w h = 2 pi). So the steps stay below
// kTurningFrameStep (rtol / kTurningFrameRtol)^(1/4) / w_max, at most kTurningFrameLongestStep
// / w_max: that error then follows rtol. Against an explicit Verner run at rtol 1e-11 three
// such pairs (1.5 and 8 rad/s about the major axis, 8 along the rod) came out 0.005 .. 1.5 rtol
// off over rtol 1e-4 .. 1e-8 (tests/core/analysis/turning_frame_test.cpp; without the bound up to
// 378 rtol at 1e-8, and 12 .. 537 rtol in fixed axes: docs/transient_measurements.md "Floating
// scenes turn with their frame"). The constants are fitted to the 8 rad/s pair: a faster spin
// couples more.
inline constexpr double kTurningFrameStep = 1.0;
inline constexpr double kTurningFrameRtol = 1e-8;
inline constexpr double kTurningFrameLongestStep = 3.0;
// A mechanism (a body not held by beams and fixed joints to the ground, in no floating part: a
// pendulum on a joint) turns its stiff directions with it too, and the estimates miss the same
// thing. A pendulum of a 0.5 kg arm on a revolute joint (relative compliance 1e-3, w_max 1.23e6
// rad/s) and a 1 kg bob on a 0.25 m rod, swinging at 4 rad/s, 1 s, came out 37.6 rtol off at
// rtol 1e-4 (auto's own steps, w_max h ~ 30; the energy check warned) against an explicit Verner
// run at rtol 1e-11; its error went as (w_max h)^6.5 and hardly with the swing (0.05, 1 and 2
// times that speed: 0.0019, 0.0020, 0.0044 rtol at w_max h = 3). On the bobs of an adversarial
// review (2 s, joints of the default compliance, under loads: no energy check) it went as
// (w_max h)^3.5 to 4: at rtol 1e-8, 7 to 16 rtol at w_max h = 1.4, 0.35 to 0.96 at 0.7, 0.02 to
// 0.15 at 0.35. So the steps stay below kMechanismStep (rtol / kMechanismRtol)^(1/4) / w_max, at
// most kMechanismLongestStep / w_max (3, 1.9, 0.6 at rtol 1e-4, 1e-6, 1e-8); but only while the
// modes above kMechanismStiffModes w_max hold more than kMechanismStiffShare of the modal energy
// (modal_stiff_share: the swing turning into the stiff directions of a stale linearization, and
// their ringing). Where the mechanism barely turns against its stiff directions they hold almost
// nothing, and the bound would cost much: a 0.5 kg bob hinged 0.2 m below the 1 kg tip of a
// cantilever (w_max 3e7 rad/s; a share of 1e-13 to 1e-10 at its steps) took 20,988 steps for 2
// s at rtol 1e-4, 0.018 rtol off, and under the bound everywhere used up 10 million. The first
// pendulum's share starts each relinearized phase at 1e-13 to 1e-9 and grows to 1e-5: with
// long first steps in each phase it stayed 6.6 rtol off at rtol 1e-4. So a phase relinearized
// where the bound held holds it from its start (ModalStepBounds::hold_mechanism, set by auto
// through hold_modal_mechanism_bound): 0.0053 / 0.0089 / 0.0018 rtol at rtol 1e-4 / 1e-6 / 1e-8.
inline constexpr double kMechanismStep = 0.6;
inline constexpr double kMechanismRtol = 1e-8;
inline constexpr double kMechanismLongestStep = 3.0;
inline constexpr double kMechanismStiffModes = 0.3;
inline constexpr double kMechanismStiffShare = 1e-8;
// The bound shortens the estimates' step kMechanismMostShorter times at most: where they were
// right it costs at most that factor. A flexible arm on a revolute joint of the default
// compliance (a 0.1 kg hub, a 0.5 m rod, a 0.5 kg tip; an adversarial review) holds energy in
// its stiff modes all along, but its runs without the bound at rtol 1e-6 and 1e-8 agreed with a
// bounded one to 1e-6 of the motion; under the bound alone it took 5 million steps for 1 s at
// 1e-6 (5,400 without) and ran out of max_steps at 1e-8; at most 10 times shorter, 27k / 43k
// / 131k steps at 1e-4 / 1e-6 / 1e-8; at most 100 times, 43k / 427k / 1.3 million. A bob
// hanging on such a joint under a 1e-2 N m harmonic torque needs more: its estimates' steps
// were far too long (421 / 316 / 1,800 rtol off before the bound), and it came out 41 / 890 /
// 33 rtol off at 10 times, 22 / 11 / 14 at 30, 0.004 / 0.07 / 4.0 at 100.
inline constexpr double kMechanismMostShorter = 100.0;
// A step the mechanism's bounds held below this part of the estimates' step counts as held
// (modal_held_steps, core/analysis/modal_integrator.hpp): where they hold nearly every step so,
// the stiff modes' ringing, not the motion, sets the steps (auto then goes on with an implicit
// method: core/analysis/auto_integrator.hpp, kAutoHeldSteps). A tenth, not a thirtieth: a
// 40-segment rod on a spherical joint (docs/transient_measurements.md "Held steps counted from
// where the hold begins") had every step from 0.01 s on held 17 times below its estimates' step
// (the stiff modes' bound, 1.9 / w_max at w_max 1.3e8 rad/s) and was not counted.
inline constexpr double kMechanismHeldShare = 0.1;
// The held steps are counted over the latest stretch of accepted steps in which at least this
// share was held (a step not held that brings the share below it starts a new stretch): a phase
// that ran free for a while before the hold began counts from where it began.
inline constexpr double kMechanismHeldStretch = 0.9;
// A mechanism's slower modes ring too, and the remainder carries their ringing into the motion
// (a joint's tension rings in its axial mode and pulls on the swing with it): the estimates
// sample that forcing at the stages of a step and do not see a step that skips its periods.
// A 1 kg bob hanging at rest 0.3 m below a revolute joint of the default compliance, released
// with the joint unstressed (so its 910 Hz axial mode rings with gravity's sag; the stiff modes
// above 0.3 w_max hold 1e-10 of the energy), under a 1e-4 N m torque at 1 Hz, 0.5 s (an
// adversarial review, 2026-11-29; against Verner at rtol 1e-11, in rtol of its 15 um swing):
// 144 / 3.5e4 / 2.5e5 off at rtol 1e-4 / 1e-6 / 1e-8 (53 / 86 / 4,095 steps), silent. With
// steps at w h = 6.1, 3.8, 2.0, 1.2, 0.6 in the ringing mode it was 12, 2.3, 0.13, 0.019, 6e-4
// times its error weights off at rtol 1e-6 (about (w h)^4). So the steps also stay below the
// mechanism's bound on w h (3 / 1.9 / 0.6 at rtol 1e-4 / 1e-6 / 1e-8, at most
// kMechanismMostShorter times shorter than the estimates' step) in the slowest of the fastest
// modes that together hold more than kMechanismRingingShare of the modal energy
// (modal_ringing_rate; the stiff modes above hold less than kMechanismStiffShare, or their own
// bound holds): 2.1 / 0.068 / 57 (981 / 1,226 / 6,991 steps). The same bob on a joint of
// compliance 1e-9 (a stiffer ringing of the same tension, holding less energy as the swing
// grows): 24 / 2.4e3 / 4.6e5 before, 3.9e-5 / 0.0039 / 0.39 held (10,000 steps each); with a
// share of 0.1 the ringing dropped out of it and the bound made it worse, 565 / 7.5e4 / 6.3e6.
// Weighted by the modes' accelerations (lambda times their energy) the stiff modes of the bob
// hinged below a cantilever (studies/hinged_bob.json) held half of it: 30 times the steps.
// What 1e-5 costs on the reviews' mechanisms: at most 3.3 times the steps at rtol 1e-4 on a bob
// on a joint of compliance 1e-9 (0.18 / 0.15 rtol off), 3.2 times at 1e-6 on the hinged bob
// (both already right); many runs took fewer (docs/transient_measurements.md "A mechanism's ringing
// modes hold its steps").
inline constexpr double kMechanismRingingShare = 1e-5;
// With a harmonic load of frequency f (the highest), the steps stay below kHarmonicStep
// rtol^(1/4) / (2 pi f): the third-order estimate compares two evaluations at the same time
// (c = 1/2) and cannot see a load's change within the step, and the second-order one saw too
// little of it. A 1 kg tip on a 0.5 m rod of 10 mm under 500 N at 20 Hz (an adversarial
// review, 2026-11-29; its centres against Verner at rtol 1e-11, in rtol at rtol 1e-4 / 1e-6
// / 1e-8) came out 21 / 60 / 125 rtol off with 769 / 2,010 / 5,381 steps, some of them long
// where the estimates missed the load; with 2 pi f h at most 0.25 / 0.079 / 0.025 (this
// bound) 0.11 / 0.088 / 0.07, with 1,075 / 3,380 / 10,404 steps.
inline constexpr double kHarmonicStep = 2.5;

// The turning frame's bound on w_max h at `rtol`: kTurningFrameStep (rtol /
// kTurningFrameRtol)^(1/4), at most kTurningFrameLongestStep.
double turning_step_bound(double rtol);

// The mechanism's bound on w_max h at `rtol`: kMechanismStep (rtol / kMechanismRtol)^(1/4), at
// most kMechanismLongestStep.
double mechanism_step_bound(double rtol);

// True when a free body moves as a mechanism: not held by beams and fixed joints to the ground
// (a pendulum on a joint, a carriage on a rail) and not part of a floating part.
bool moves_as_mechanism(const Model& model);

// The share of the modal energy sum 1/2 (zdot_i^2 + lambda_i z_i^2) in the modes above
// kMechanismStiffModes w_max: `lambda` the modes' eigenvalues, `z` their displacements (column 0)
// and velocities (column 1) from the linearization's reference.
double modal_stiff_share(const Eigen::ArrayXd& lambda, const ModeBlock& z);

// The frequency [rad/s] of the slowest of the fastest modes that together hold more than `share`
// of that modal energy: `order` the modes from the fastest down; 0 when no mode holds energy.
double modal_ringing_rate(const Eigen::ArrayXd& lambda, const std::vector<Eigen::Index>& order,
                          const ModeBlock& z, double share);

// A step of the modal method is exact for the linear part of the motion, so on a nearly linear
// motion nothing in its error asks for short steps, and the range of the element laws (a
// carriage's travel, a beam through zero length), checked at the step's evaluations, could be
// left and regained between them: a carriage on a soft spring swinging with a 0.75 s period,
// sampled at 0.25 s steps, dipped 30 mm out of its travel unseen (an adversarial review); and
// the warnings of the range (kSmallAngleLimit, kRailTravelWarning in
// core/analysis/deformation_check.hpp), watched at every accepted step, could be passed and
// regained between two (a disc twisting 0.8 rad and back). So a step resolves the modes that
// could carry an element across the nearest of those edges: no longer than kResolvedPhase / w,
// w the frequency of the slowest of the fastest oscillating modes whose swings together reach
// kEdgeShare of the element's margin to it (modal_edge_rate). The margins: in length
// (element_margins: a beam's axial extent, a carriage's distance to its travel's ends or
// to its travel warning), in angle (element_margins: to the small-angle warning, past it to
// the limit of the element's measure). A mode's swing is its amplitude about the static state of
// the forces at the step's start (modal_swing) times the largest change it makes in an element's
// point 2 relative to its left end, or in its relative rotation (element_reach): counted as the
// largest translation it gives a body, a twist that swung a rail's point 2.9 m from its body's
// centre counted as no motion, and a rail between two bodies swinging against each other as half
// its motion, and both left their travels between two steps, ok (an adversarial review). Over
// its period a mode moves at most twice its swing from where it is, so the modes left unresolved
// cannot carry an element across its margin, and the evaluations of a resolved mode, half a step
// apart, lie at most pi / 16 apart in its phase: an excursion they miss is at most 1 - cos(pi /
// 32), 0.5 %, of its swing. (About the linearization instead, a static deflection would count as
// a swing, and an element held near an edge would have every step held.) Until 2026-12-02 the
// steps resolved the fastest modes holding 1 % of the sum of the swings wherever the edges were:
// the braced tower (docs/transient_measurements.md) then took 17,653 steps and 32.0 s for its 1 s
// at rtol 1e-5 (1,884 steps and 5.4 s without). On mechanisms too (a first form left them to
// their ringing bound, and a carriage free on its rail anywhere in a scene switched the bound off
// for a spring-held one elsewhere, which left its travel unseen: an adversarial review); but a
// rigid mode (lambda <= 0) has no swing, so its path between two evaluations (a carriage thrown
// past its travel and back within a step) is not bounded by this: modal_slow_edge_step is.
inline constexpr double kResolvedPhase = 3.14159265358979323846 / 8.0;
inline constexpr double kEdgeShare = 0.5;
// A rigid mode (lambda <= 0) has no swing, and a slow one swings about a static state far away:
// over a step both move along near parabolas, and a path that leaves an element's range and
// comes back between two evaluations is not seen (a carriage thrown up a rail against a constant
// force, past its travel's end and back within one step of 0.5 s, ok; found 2026-12-02). Between
// two accepted states h apart (where the warnings are watched; the stages are h / 2 apart) a
// path of acceleration a passes the larger of its two ends by at most |a| h^2 / 8. So a step
// stays below sqrt(8 kSlowEdgeShare m / d) for each element of margin m, d how far the
// accelerations of the modes the step resolves anyway (lambda_i h^2 <= kResolvedPhase^2) move it
// together (modal_slow_edge_step).
inline constexpr double kSlowEdgeShare = 0.25;

// How far each mode moves each element (the beams, then the rails) per unit of its coordinate:
// `length` (modes x elements) the first-order change |d xi| of the element's point 2 in its
// left-end frame, xi = E1^T (p2 - p1), `angle` the change |d theta_2 - d theta_1| of its relative
// rotation (of a cylindrical rail without the part about its axis, where it turns freely: its
// angle measure does not see it), and `largest` (modes x 2) the largest of each over the elements:
// d xi = d p2 - d p1 - d theta_1 x (p2 - p1), d p_k = d c_k + d theta_k x R_k (R_k the centre ->
// point k arm), from each body's offsets (d c, d theta) in `phi` (6 rows per free body,
// core/analysis/modal_coordinates.hpp; fixed bodies do not move) about the configuration of
// data.pose. In a frame that turns with a floating part both ends turn with it: the lengths are
// the same.
// `levers` per element: what maps offsets to its motion (element_motion).
struct ElementLever {
  int row1, row2;  // the first of the bodies' 6 rows in phi; -1: fixed
  Vec3 arm1, arm2, span;
  Vec3 free_axis;  // a cylindrical rail's axis, about which it turns freely; else zero
};
struct ElementReach {
  Eigen::ArrayXXd length, angle;
  Eigen::ArrayX2d largest;
  std::vector<ElementLever> levers;
};
ElementReach element_reach(const Model& model, const Data& data, const Eigen::MatrixXd& phi);

// How far the offsets `v` (6 rows per free body, as a column of phi) move each element, as
// element_reach counts a mode's: `length` |d xi|, `angle` the relative rotation's change.
void element_motion(const ElementReach& reach, const Eigen::Ref<const Eigen::VectorXd>& v,
                    Eigen::ArrayXd* length, Eigen::ArrayXd* angle);

// Each oscillating mode's amplitude about the static state of the forces at the state z (column
// 0 displacements, 1 velocities): sqrt(((psi_a_i + c_i zdot_i) / lambda_i)^2 + zdot_i^2 /
// lambda_i), psi_a = Phi^T M0 a the modal accelerations there, c_i the mode's damping (empty:
// none); 0 for lambda_i <= 0.
Eigen::ArrayXd modal_swing(const Eigen::ArrayXd& lambda, const Eigen::ArrayXd& damping,
                           const ModeBlock& z, const Eigen::ArrayXd& psi_a);

// The frequency [rad/s] of the slowest of the fastest oscillating modes whose swings
// reach_i swing_i together pass `share` times `margin`; `order` the modes from the fastest down;
// 0 when none do.
double modal_edge_rate(const Eigen::ArrayXd& lambda, const std::vector<Eigen::Index>& order,
                       const Eigen::ArrayXd& swing, const Eigen::Ref<const Eigen::ArrayXd>& reach,
                       double margin, double share);

// The largest modal_edge_rate over the elements, each with its own reach and margins
// (element_margins in core/analysis/deformation_check.hpp): an element near its edge bounds the
// steps only by the modes that move it (with the smallest margin against the largest reach, a
// carriage standing 0.1 um from its travel's end held the steps of a scene to a steel link's
// 8.4e4 rad/s ringing that cannot move it: 214,000 steps a second; an adversarial review). An
// element is looked at only where the largest reach's swings could carry it across.
// The longest step [s], at most `h`, over which the modes slower than h resolves (lambda_i h^2 <=
// kResolvedPhase^2, every rigid mode) cannot carry an element across `share` of its margin
// unseen: sqrt(8 share m_e / d_e) over the elements e (margins m_e), d_e how far their
// accelerations together move it (element_motion of phi a_slow; `accel` the modes'
// accelerations at the accepted state, `phi` their shapes). Together, not each by itself: rigid
// modes come as any mix of a floating pair's common and relative motions, and counted one by one
// a pair falling together with a carriage 1e-8 m from its travel's end took 313,191 steps for
// 10 s where 7 did (an adversarial review).
double modal_slow_edge_step(const Eigen::ArrayXd& lambda, const Eigen::ArrayXd& accel,
                            const Eigen::MatrixXd& phi, const ElementReach& reach,
                            const std::vector<double>& length_margins,
                            const std::vector<double>& angle_margins, double h, double share);

double modal_elements_edge_rate(const Eigen::ArrayXd& lambda,
                                const std::vector<Eigen::Index>& order, const Eigen::ArrayXd& swing,
                                const ElementReach& reach,
                                const std::vector<double>& length_margins,
                                const std::vector<double>& angle_margins, double share);

// z for the bounds of a step from a state where the forces may set modes ringing that do not
// ring yet (a mechanism's first step, at the start or at a load's jump): each mode's
// displacement from the static state of the forces at the step's start, |psi_a_i| / lambda_i
// (psi_a = Phi^T M0 a, the modal accelerations), where that is larger than |z_i| (modes of
// lambda_i <= 0 as they are). A mode's energy is then the larger of its own and of its ringing
// about that static state. At rest no mode holds energy, so neither the stiff modes' bound nor
// the ringing one held the first step, which spanned a whole output interval: a 2 kg carriage
// on a prismatic rail guide carrying a two-segment cantilever, released at rest and unstressed
// under gravity and pushed along the rail by 1 mN at 1 Hz (an adversarial review, 2026-11-29),
// kept that step's velocity error along the rail, and after 1 s it was 0.11 / 12 / 5.4 rtol of
// its motion off at rtol 1e-4 / 1e-6 / 1e-8 (against Verner at rtol 1e-11), silent; with its
// first step held so, 0.026 / 0.077 / 0.010. At every start (the run's, a load's jump, auto's
// relinearization), at rest or not: a first form asked for exact rest, and a carriage nudged at
// 1e-12 m/s along its rail kept the error. What it does on the reviews' other mechanisms:
// docs/transient_measurements.md "A mechanism's first step from rest".
ModeBlock ringing_about_static_state(const Eigen::ArrayXd& lambda, const ModeBlock& z,
                                     const Eigen::VectorXd& psi_a);

// The bounds of one linearization [s]; 0: none.
struct ModalStepBounds {
  double turning = 0.0;         // in a turning frame (kTurningFrameStep)
  double mechanism = 0.0;       // a mechanism's, while its stiff modes hold energy (kMechanismStep)
  double mechanism_wh = 0.0;    // a mechanism's bound on w h (kMechanismRingingShare)
  double harmonic = 0.0;        // with harmonic loads (kHarmonicStep)
  bool hold_mechanism = false;  // the mechanism's bound from the start, whatever the share

  // `w_max` the fastest mode integrated [rad/s] (0: no turning or mechanism bound);
  // `harmonic_hz` the highest harmonic load's frequency (0: none).
  ModalStepBounds(double rtol, double w_max, bool turning_frame, bool mechanism_moves,
                  double harmonic_hz);
  ModalStepBounds() = default;

  // The step `h` within the bounds; `estimates` the step the error estimates ask for;
  // `mechanism_holds`: the mechanism's bound holds (hold_mechanism, or its stiff modes hold more
  // than kMechanismStiffShare of the energy); else, for a mechanism, `ringing_rate` the frequency
  // of its ringing modes [rad/s] (modal_ringing_rate, kMechanismRingingShare; 0: none).
  double limit(double h, double estimates, bool mechanism_holds, double ringing_rate) const;
};

}  // namespace beamrail
