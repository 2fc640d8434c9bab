#include "optimizer/run/transient_checks.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <limits>

#include "core/analysis/modal_step_bounds.hpp"
#include "core/model/forces.hpp"
#include "optimizer/run/number_text.hpp"

namespace beamrail {
namespace {

std::string two_digits(double x) {
  char text[32];
  std::snprintf(text, sizeof text, x >= 99.5 ? "%.0f" : "%.2g", x);
  return text;
}

// Whether a method is one of CVODE's multistep methods, by name ("bdf", "adams") or as a phase
// of an auto run ("bdf", ...).
bool multistep(IntegratorMethod method) {
  return method == IntegratorMethod::kBdf || method == IntegratorMethod::kAdams;
}

bool multistep(const std::string& phase_method) {
  return phase_method.rfind("bdf", 0) == 0 || phase_method.rfind("adams", 0) == 0;
}

// What a multistep run's verification says of why: where CVODE's error control was found off.
const char kMultistepFindings[] =
    "whose error control was found up to 6,400 times its tolerance off without a sign on "
    "scenes that are no mechanism (damped spinning pairs, a free body under follower loads, a "
    "damped tip on a cantilever: docs/transient_measurements.md \"Multistep runs verify "
    "themselves\")";

// The reason of a verification by default ("verify": "auto"): why, and how to skip it.
std::string by_default(const std::string& why) {
  return "\"verify\": \"auto\", the default: " + why + "; \"verify\": false skips the rerun";
}

}  // namespace

// Whether a rail reached its min_length in the run (its law has a kink there, at which the
// energy jumps by more than the steps' error; the run says so in its own warning).
bool rail_floored(const Data& data) {
  return std::any_of(data.rail_floored_ever.begin(), data.rail_floored_ever.end(),
                     [](char c) { return c != 0; });
}

// The warning of a scene that keeps its energy (conserves_energy) whose run changed it by more
// than kDriftTolerance rtol of the energy in play ("" for any other run), as its error may then be
// far above rtol. Adaptive runs of the whole model only (a fixed step's error is not rtol's; a band
// drops the energy of the modes above it by design), and above the rounding of the energy's terms
// over the steps (reference runs at rtol 1e-11 and below drift by rounding: a pendulum of 2.25
// million steps by 1.5e-11 J of 3.8 J, a body 10 km above the origin by a few ulp of its
// gravity energy). Measured (docs/transient_measurements.md "Energy drift and verify warn"): free
// elastic pairs spinning, auto at rtol 1e-4 and 1e-6, drifts of 12 to 208 rtol where the motion was
// 12 to 537 rtol off; the tumbling pair within 7 rtol where its centres are within 2.
std::string energy_drift_warning(const AnalysisSpec& spec, const Model& model,
                                 const TransientOptions& options, double drift,
                                 const EnergyScales& energy, long steps) {
  const double rtol = options.integrator.rtol;
  if (options.integrator.fixed_step > 0.0 || !(energy.moving > 0.0) || !conserves_energy(model))
    return "";
  const double rounding = std::numeric_limits<double>::epsilon() * energy.terms *
                          static_cast<double>(std::max(1L, steps));
  const double ratio = drift / energy.moving;
  if (!(ratio > kDriftTolerance * rtol) || !(drift > rounding)) return "";
  return "transient \"" + spec.name + "\": the energy changed by " + two_digits(ratio) +
         " of the largest kinetic + elastic energy (" + two_digits(ratio / rtol) +
         " rtol) in a scene that keeps it (no loads, no damping): the motion may be "
         "off by more than rtol; \"verify\": true measures it (a mechanism is verified by "
         "default)";
}

// Why the transient is verified (summary.json verification.reason), "" when it is not: asked
// ("verify": true), or by default ("auto") where its steps are adaptive and
// - its scene moves as a mechanism (a body not held by beams and fixed joints to the ground, and
//   not part of a floating part: a pendulum on a joint, a carriage on a rail). There every
//   method's error control was found silently off, by up to 1e4 times rtol, where no other check
//   saw it (docs/transient_measurements.md "Mechanisms verify themselves"); a rerun at rtol / 10
//   measured each such run's error and warned of every one beyond 10 times its tolerance. It costs
//   the rerun: 1.8 times the run's time at the median of 63 review runs, at most 2.5 times in 45 of
//   them, 65 times at worst;
// - or bdf or adams integrates it (by name) and a body is free. Their error on structures and
//   free bodies was found up to 61 times the tolerance off, silent (damped spinning pairs: up to
//   6,400), and their reruns at rtol / 10 measured 0.77 to 1.09 of it against tight independent
//   runs (an adversarial review: 0.24 to 1.85, median 0.84, over 141 runs more than 10
//   tolerances off; docs/transient_measurements.md "Multistep runs verify themselves"), at about
//   the run's own cost.
std::string verification_reason(const AnalysisSpec& spec, const Model& model,
                                const TransientOptions& options) {
  switch (spec.verify) {
    case AnalysisSpec::Verify::kAlways:
      return "asked (\"verify\": true)";
    case AnalysisSpec::Verify::kNever:
      return "";
    case AnalysisSpec::Verify::kAuto:
      break;
  }
  if (options.integrator.fixed_step > 0.0) return "";
  if (moves_as_mechanism(model))
    return by_default(
        "bodies move as a mechanism (not held by beams and fixed joints to the ground), where "
        "error control was found far off without a sign");
  if (multistep(options.integrator.method) && model.n_free() > 0)
    return by_default(std::string(method_name(options.integrator.method)) +
                      " integrates the run, " + kMultistepFindings);
  return "";
}

// Whether a transient that verification_reason does not verify may be verified after its run
// (verified_after_the_run): "verify": "auto" on an adaptive auto run.
bool may_verify_after_the_run(const AnalysisSpec& spec, const TransientOptions& options) {
  return spec.verify == AnalysisSpec::Verify::kAuto && options.integrator.fixed_step <= 0.0 &&
         options.integrator.method == IntegratorMethod::kAuto;
}

// Why a transient is verified after its run, "" when it is not: by default ("auto") an auto run
// - that handed a phase to bdf (a modal method that could not start), for the reason
//   verification_reason verifies bdf by name;
// - or that relinearized as a body turned its limit. Its motion is then not a small one about a
// configuration, where the modal method's error estimates were measured to hold; along large
// motions the error can grow far past rtol with no other sign: an L-frame (a 1 m steel
// cantilever in 5 segments, a 0.6 m leg from its 1 kg tip to a 2 kg foot, the tip started at
// 2.2 m/s; an adversarial review, 2026-11-30) came out 10 / 1,150 rtol off at rtol 1e-3 / 1e-5
// against Verner at rtol 1e-11, warned only of its model (the beams' axial forces), and its
// reruns measured 13 / 1,022 (docs/transient_measurements.md "Large motions verify themselves").
// Not where auto only handed over to dirk after a failed modal phase: a 100-segment cantilever
// whose band failed at 3 us ran dirk, and its rerun at rtol 1e-7 was itself 21 times farther off
// than the run (a false alarm).
bool phase_verifies(const Model& model, const MethodPhase& phase) {
  return (multistep(phase.method) && model.n_free() > 0) || phase.relinearized;
}

std::string verified_after_the_run(const AnalysisSpec& spec, const Model& model,
                                   const TransientOptions& options, const TransientResult& result) {
  if (!may_verify_after_the_run(spec, options)) return "";
  const auto phase = std::find_if(result.phases.begin(), result.phases.end(),
                                  [](const MethodPhase& p) { return multistep(p.method); });
  if (phase != result.phases.end() && model.n_free() > 0)
    return by_default("auto handed the run to " + phase->method +
                      " at t = " + format_number(phase->t) + " s, " + kMultistepFindings);
  if (std::none_of(result.phases.begin(), result.phases.end(),
                   [&](const MethodPhase& p) { return phase_verifies(model, p); }))
    return "";
  return by_default("the run relinearized as bodies turned (" + std::to_string(result.phase_count) +
                    " phases): a large motion, where error control was found far off without a "
                    "sign");
}

// The distances in multiples of the tolerance: in the centres rtol x + atol, x the rerun's
// largest motion [m]; in the orientations rtol max(x, 1 rad) + atol radians, x the largest angle
// a body of the rerun turned along its samples (every method weights a rotation absolutely,
// about rtol radians per step: a carriage tilting 3.7e-4 rad on a rail was 4.8e-8 rad off at
// rtol 1e-6, 129 rtol of its turn; a spin's phase error grows with the angle turned: the
// tumbling pair's 27 rad, about 3 rtol per radian). The orientations only where successive
// samples are within kLongestSampledTurn (else a sample may have skipped a turn and the angle
// turned is not known: turned is NaN); the centres still count there. A fixed step's error is
// not its tolerances': NaN.
void weigh_verification(const TransientOptions& options, Verification* v) {
  const double rtol = options.integrator.rtol, atol = options.integrator.atol;
  v->tolerances = v->rotation_tolerances = std::numeric_limits<double>::quiet_NaN();
  if (!v->ok || options.integrator.fixed_step > 0.0) return;
  if (v->motion > 0.0) v->tolerances = v->error * v->motion / (rtol * v->motion + atol);
  if (v->turned > 0.0)
    v->rotation_tolerances =
        v->rotation_error * v->turn / (rtol * std::max(v->turned, 1.0) + atol);  // [rad] / [rad]
}

namespace {

// What was rerun: the run, or the refined run that replaced it.
std::string rerun_description(const std::optional<Refinement>& refinement) {
  if (!refinement) return "the verification rerun";
  const Verification& first = refinement->first_run;
  return "its verification rerun found the run " +
         two_digits(std::max(first.tolerances >= 0.0 ? first.tolerances : 0.0,
                             first.rotation_tolerances >= 0.0 ? first.rotation_tolerances : 0.0)) +
         " times its tolerance off, so it was run again at rtol " + two_digits(first.rtol) +
         " (\"refine\"), and that run's verification rerun";
}

}  // namespace

std::string verification_out_of_range(const Verification& v,
                                      const std::optional<Refinement>& refinement) {
  if (v.ok || !v.out_of_range) return "";
  std::string rerun = rerun_description(refinement);
  rerun[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(rerun[0])));
  return rerun + " at rtol " + two_digits(v.rtol) +
         " failed where an element left the range of its law (" + v.message +
         "), which the run stepped over: its results from there on are not the model's; a run at "
         "rtol " +
         two_digits(v.rtol) + " or with a shorter max_step stops there";
}

// The warning of a verification rerun farther from the run than kDriftTolerance times its
// tolerance (weigh_verification; "" when it is within it, or for a fixed step; a rerun that
// failed warns that it measured nothing).
std::string verification_warning(const AnalysisSpec& spec, const TransientOptions& options,
                                 const Verification& v,
                                 const std::optional<Refinement>& refinement) {
  const double rtol = options.integrator.rtol;
  const std::string rerun = rerun_description(refinement);
  if (!v.ok) {
    // A rerun that did not finish measured nothing (the run at rtol 1e-8 of a carriage with a
    // pendulum under a harmonic force: its rerun spent max_steps in 50 s, the run took 10 s).
    // Verified by default, the user did not ask for it: say how to skip it (a sweep whose
    // designs fit max_seconds_per_design but whose reruns do not warned on every row; an
    // adversarial review of bdf's verification, 2026-11-30).
    const bool unasked = spec.verify == AnalysisSpec::Verify::kAuto;
    return "transient \"" + spec.name + "\": " + rerun + " failed (" + v.message +
           "): the run's error is not measured" +
           (unasked ? "; give it more max_seconds or max_steps, or \"verify\": false skips it"
                    : "");
  }
  if (options.integrator.fixed_step > 0.0) return "";
  std::string what;
  // Each figure also in multiples of the tolerance, which decides: where atol dominates it, the
  // rtol figure alone reads far larger (a bob swinging 78 um: 1.8e4 rtol, 140 tolerances).
  if (v.tolerances > kDriftTolerance)
    what = "the body centres by " + two_digits(v.error) + " of their motion (" +
           two_digits(v.tolerances) + " times their tolerance rtol x + atol; " +
           two_digits(v.error / rtol) + " rtol)";
  if (v.rotation_tolerances > kDriftTolerance) {
    const double angle = v.rotation_error * v.turn;  // [rad]
    what += (what.empty() ? "" : " and ") + std::string("the orientations by ") +
            two_digits(angle) + " rad (" + two_digits(v.rotation_tolerances) +
            " times their tolerance; " + two_digits(angle / v.turned / rtol) + " rtol of the " +
            two_digits(v.turned) + " rad turned)";
  }
  if (what.empty()) return "";
  // bdf's and adams' error need not fall with rtol (a damped spinning pair under bdf: 2 to 5,400
  // tolerances off over rtol 1e-4 .. 1e-10, growing as rtol shrinks; an adversarial review,
  // 2026-11-30), so for them another method is the other way out.
  const bool multistep_by_name = multistep(options.integrator.method);
  if (refinement)
    return "transient \"" + spec.name + "\": " + rerun + " at rtol " + two_digits(v.rtol) +
           " moved " + what +
           ": the results, those of the refined run, are not within the tolerance asked either; "
           "run it at a smaller rtol" +
           (multistep_by_name ? " or with another method (auto, dirk)" : "");
  return "transient \"" + spec.name + "\": the verification rerun at rtol / 10 moved " + what +
         ": the run is not within its tolerance; run it at a smaller rtol" +
         (multistep_by_name ? " or with another method (auto, dirk)" : "");
}

}  // namespace beamrail
