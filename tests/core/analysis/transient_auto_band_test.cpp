// The "auto" method's bands (core/analysis/auto_integrator.hpp, max_frequency_hz): chosen for
// rtol, given, widened, and where a modal phase fails; band-limited modal runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "core/analysis/auto_integrator.hpp"
#include "core/analysis/modal_integrator.hpp"
#include "core/scene/scene_loader.hpp"
#include "tests/support/heavy_tip_cantilever.hpp"
#include "tests/support/reference_cantilever.hpp"
#include "tests/support/stiff_joint_bob.hpp"
#include "tests/support/transient_run.hpp"

namespace beamrail {
namespace {

using testing::motion_error;
using testing::options;
using testing::reference_cantilever;
using testing::run_error;
using testing::run_with;
using testing::scene_from_json;
using testing::simulate;
using testing::tight;
using testing::TransientRun;

// Beyond the dense eigensolver's size for a band (kModalDenseBandMaxDofs), auto chooses a band
// for rtol from Lanczos's modes (core/analysis/modal_band.hpp) and integrates the modes in it;
// when no band of the modes it may ask for meets rtol, every mode up to kModalIntegratorMaxDofs
// (once bdf: 187k steps where every mode took 1,366 at rtol 1e-7, docs/transient_measurements.md
// "Every mode where no band meets rtol"), and bdf beyond.
TEST(TransientAuto, BeyondTheDenseLimitChoosesABandElseEveryModeElseBdf) {
  const int bodies = kModalDenseBandMaxDofs / kDofsPerBody + 1;
  const Model model = scene_from_json(reference_cantilever(bodies));
  // Over 0.05 s (past a quarter of the lowest period: the motion is the static response's size).
  const TransientRun run = run_with(model, "auto", 0.05, 0.01, 1e-6);
  ASSERT_TRUE(run.result.ok) << run.result.message;
  ASSERT_EQ(run.result.phases.size(), 1u);
  EXPECT_EQ(run.result.phases[0].method, "modal");
  const std::string& why = run.result.phases[0].reason;
  double band = 0.0;
  int modes = 0, all = 0;
  const size_t at = why.find("band ");
  ASSERT_NE(at, std::string::npos) << why;
  ASSERT_EQ(
      std::sscanf(why.c_str() + at, "band %lf Hz chosen for rtol: %d of %d", &band, &modes, &all),
      3)
      << why;
  EXPECT_EQ(all, kDofsPerBody * bodies);
  EXPECT_GT(modes, 20);
  EXPECT_LT(modes, 200);
  // At rtol 1e-6 over 10 us the high modes are most of what moves: no band of the
  // kModalChosenBandMaxModes lowest modes meets rtol, and every mode is integrated. Against bdf
  // at rtol 1e-11 (a motion of 1e-8 m: the tolerance is mostly atol, 1e-8 m).
  const double rtol = 1e-6, atol = 1e-2 * rtol;
  const TransientRun early = run_with(model, "auto", 1e-5, 1e-6, rtol);
  ASSERT_TRUE(early.result.ok) << early.result.message;
  ASSERT_EQ(early.result.phases.size(), 1u);
  EXPECT_EQ(early.result.phases[0].method, "modal");
  EXPECT_NE(early.result.phases[0].reason.find("every mode integrated"), std::string::npos)
      << early.result.phases[0].reason;
  const TransientRun reference = run_with(model, "bdf", 1e-5, 1e-6, 1e-11);
  ASSERT_TRUE(reference.result.ok) << reference.result.message;
  double error = 0.0, motion = 0.0;
  for (int b : model.free_bodies) {
    const testing::BodyDeviation d = testing::body_deviation(early, reference, b);
    error = std::max(error, d.error);
    motion = std::max(motion, d.motion);
  }
  std::printf(
      "%d bodies over 10 us at rtol 1e-6: every mode, %.2e m off bdf at 1e-11 (motion "
      "%.2e m: %.2g times its tolerance)\n",
      bodies, error, motion, error / (rtol * motion + atol));
  EXPECT_LT(error, 10.0 * (rtol * motion + atol));
  // Beyond kModalIntegratorMaxDofs: bdf.
  const int more = kModalIntegratorMaxDofs / kDofsPerBody + 1;
  const Model larger = scene_from_json(reference_cantilever(more));
  const TransientRun beyond = run_with(larger, "auto", 1e-5, 1e-5, rtol);
  ASSERT_TRUE(beyond.result.ok) << beyond.result.message;
  ASSERT_EQ(beyond.result.phases.size(), 1u);
  EXPECT_EQ(beyond.result.phases[0].method, "bdf");
  EXPECT_NE(beyond.result.phases[0].reason.find("no band of the 400 lowest modes"),
            std::string::npos)
      << beyond.result.phases[0].reason;
}

// A band whose quasi-static modes the motion pulls along at second order widens before its first
// step (ModalExponential::measure_pull, core/analysis/modal_exponential.hpp). A 1 kg tip on a
// 10-segment cantilever (10 mm square steel) under 300 N from the start (a static deflection of
// 0.57 m), at rtol 1e-4, auto's band chosen for rtol. Its band's quasi-static iteration used to
// diverge at t = 0 (its Newton matrix took the rotation vectors' increments for rotations), and
// auto went on with every mode: 2.1 rtol against an explicit Verner run at rtol 1e-10. With that
// matrix right, the bands ran (37 to 891 Hz, relinearized every 5 to 40 ms, each phase too short
// for the dropped inertia's check to settle) and the run ended 0.056 of the motion off (558
// rtol), warned. Now the pull at the start (0.11 of the band's kinetic energy, the tip drawn in
// along the stiff axis as it swings; the run measured 0.19) widens it at t = 0: 1.4 rtol.
TEST(TransientAuto, ABandWhoseQuasiStaticModesArePulledAlongWidensBeforeItsFirstStep) {
  const Model model = scene_from_json(testing::heavy_tip_cantilever(R"("value": [0, -300, 0])"));
  const double rtol = 1e-4;
  TransientOptions o = options(0.5, 5e-3, rtol, 1e-3 * rtol);
  o.integrator.method = IntegratorMethod::kAuto;
  o.integrator.choose_band = true;
  const TransientRun run = simulate(model, o);
  ASSERT_TRUE(run.result.ok) << run.result.message;
  const TransientRun reference = tight(model, 0.5, 5e-3, 1e-10);
  ASSERT_TRUE(reference.result.ok) << reference.result.message;
  const std::vector<MethodPhase>& phases = run.result.phases;
  const auto widened = std::find_if(phases.begin(), phases.end(), [](const MethodPhase& p) {
    return p.reason.find("would move with") != std::string::npos;
  });
  ASSERT_NE(widened, phases.end());
  EXPECT_EQ(widened->t, 0.0);
  EXPECT_NE(widened->reason.find("every mode integrated from here"), std::string::npos)
      << widened->reason;
  for (const MethodPhase& p : phases) EXPECT_EQ(p.method, "modal") << p.reason;
  const double error = run_error(model, run, reference);
  std::printf("%s\n%ld phases, %ld steps: error %.2e (%.2f rtol)\n", widened->reason.c_str(),
              run.result.phase_count, run.result.stats.steps, error, error / rtol);
  EXPECT_LE(error, 10.0 * rtol);
  EXPECT_GE(error, 1e-3 * rtol);
  // Nothing dropped: no band ran a step.
  for (const std::string& w : run.result.warnings)
    EXPECT_EQ(w.find("band-limited run"), std::string::npos) << w;
}

// A 0.5 kg tip on a 1 m cantilever of 10 mm square steel in 40 segments under a step of `force`
// N at `at` s.
Model bent_cantilever(double force, double at = 0.0) {
  return scene_from_json(R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"sq10": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [{"name": "tip", "mass": 0.5, "inertia": [1e-5, 1e-5, 1e-5], "position": [1, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq10",
               "segments": 40}],
    "loads": [{"type": "force", "body": "tip", "value": [0, )" +
                         std::to_string(-force) + R"(, 0],
               "time": {"type": "step", "at": )" +
                         std::to_string(at) + R"(}}]})");
}

// The cantilever above for 0.02 s: `dirk` at rtol 1e-9 (the reference) and `auto` in a given band
// of 30 Hz (its two first bending modes) at rtol 1e-4.
struct BandAgainstDirk {
  TransientRun reference, run;
};
constexpr double kBentRtol = 1e-4;
BandAgainstDirk bent_cantilever_band(const Model& model) {
  const double t_end = 0.02, output_step = 2e-3;
  TransientOptions o = options(t_end, output_step, 1e-9, 1e-12);
  o.integrator.method = IntegratorMethod::kDirk;
  BandAgainstDirk out;
  out.reference = simulate(model, o);
  o = options(t_end, output_step, kBentRtol, 1e-3 * kBentRtol);
  o.integrator.method = IntegratorMethod::kAuto;
  o.integrator.max_frequency_hz = 30.0;
  out.run = simulate(model, o);
  return out;
}

// Where the modal method fails, auto goes on from the last accepted state (issue 17: a default
// that never collapses): in a band given, with dirk. The heavy tip above: the modal method alone
// in a band chosen for rtol fails (at 0.14 s, "the forces became non-finite"). The cantilever
// below in a given band of 30 Hz (its two first bending modes) under a step of 500 N at 4 ms:
// the band's quasi-static iteration fails at the step (the heavy tip's given bands of 100 to 600
// Hz, whose runs went on with dirk from 0.196 s until the iteration could take its tangent again
// where it stalled or shrank slowly, now run through, warned), and dirk goes on from there, the
// run as close to dirk's alone as rtol asks (the band ran at rest until then).
TEST(TransientAuto, AFailedModalPhaseGoesOnWithTheImplicitMethod) {
  {
    const Model model = scene_from_json(testing::heavy_tip_cantilever(R"("value": [0, -300, 0])"));
    TransientOptions o = options(0.5, 5e-3, 1e-4, 1e-7);
    o.integrator.method = IntegratorMethod::kModal;
    o.integrator.choose_band = true;
    const TransientRun modal = simulate(model, o);
    EXPECT_FALSE(modal.result.ok) << "the modal method alone no longer fails here";
  }
  const Model model = bent_cantilever(500.0, 0.004);
  const double rtol = kBentRtol;
  const BandAgainstDirk runs = bent_cantilever_band(model);
  const TransientRun &reference = runs.reference, &run = runs.run;
  ASSERT_TRUE(reference.result.ok) << reference.result.message;
  ASSERT_TRUE(run.result.ok) << run.result.message;
  const std::vector<MethodPhase>& phases = run.result.phases;
  ASSERT_EQ(phases.size(), 2u);
  EXPECT_EQ(phases[0].method, "modal");
  EXPECT_EQ(phases[1].method, std::string("dirk ") + kAutoImplicitTable);
  EXPECT_EQ(phases[1].reason.find("the modal method failed ("), 0u) << phases[1].reason;
  EXPECT_DOUBLE_EQ(phases[1].t, 0.004);
  const double error = run_error(model, run, reference);
  std::printf("dirk from t = %.3g s, %ld steps in all: error %.2e (%.3g rtol)\n", phases[1].t,
              run.result.stats.steps, error, error / rtol);
  EXPECT_LT(error, rtol);
}

// Where a band's quasi-static iteration fails at the accepted state itself (here at the start),
// the modal method reports the state it had accepted, not the iteration's diverged one
// (nonlinear_at_accepted, core/analysis/modal_exponential.hpp). The cantilever above under 20 N in
// a band of 30 Hz given (an adversarial review, 2026-12-03): auto's dirk went on at t = 0 from
// that diverged state, the tip moving up against the load with 4.0 J the scene never had, and
// ran out of its 60 s at 0.124 s of 0.5 s, 1.5e4 rtol off at rtol 1e-6. Under 20 to 200 N that
// band now runs (below); under 500 N its iteration still fails at the start, and under 400 N its
// quasi-static part at the start turns the tip past the rotation limit of every linearization
// there (auto goes on with dirk after three, and says so). Here (0.02 s, rtol 1e-4) the first
// output agrees with dirk's alone, and no warning of the band stands.
TEST(TransientAuto, AModalPhaseFailedAtItsStartHandsOverTheStateItAccepted) {
  const std::pair<double, const char*> cases[] = {
      {500.0, "the modal method failed ("},
      {400.0, "relinearizing without a step, three times running (body \"tip\" 0.5 rad"}};
  for (const auto& [force, why] : cases) {
    SCOPED_TRACE(force);
    const Model model = bent_cantilever(force);
    const double rtol = kBentRtol;
    const BandAgainstDirk runs = bent_cantilever_band(model);
    const TransientRun &reference = runs.reference, &run = runs.run;
    ASSERT_TRUE(reference.result.ok) << reference.result.message;
    ASSERT_TRUE(run.result.ok) << run.result.message;
    const std::vector<MethodPhase>& phases = run.result.phases;
    ASSERT_GE(phases.size(), 2u);  // the modal phases (relinearized at t = 0 as the tip turns)
    for (size_t k = 0; k + 1 < phases.size(); ++k) {
      EXPECT_EQ(phases[k].method, "modal") << phases[k].reason;
      EXPECT_EQ(phases[k].t, 0.0);
    }
    EXPECT_EQ(phases.back().method, std::string("dirk ") + kAutoImplicitTable);
    EXPECT_EQ(phases.back().t, 0.0);
    EXPECT_EQ(phases.back().reason.find(why), 0u) << phases.back().reason;
    // The tip at the first output: pulled down by the load, as dirk's alone.
    size_t tip = 0;
    while (tip < model.bodies.size() && model.bodies[tip].name != "tip") ++tip;
    ASSERT_LT(tip, model.bodies.size());
    const double y_run = run.samples[1].c[tip](1), y_reference = reference.samples[1].c[tip](1);
    const double e = run_error(model, run, reference);
    std::printf("%g N: tip at t = %.3g s: %.6e m (dirk alone %.6e m); %ld steps, %.3g rtol off\n",
                force, run.samples[1].sample.t, y_run, y_reference, run.result.stats.steps,
                e / rtol);
    EXPECT_LT(y_run, 0.0);
    EXPECT_NEAR(y_run, y_reference, 1e-3 * std::abs(y_reference));
    EXPECT_LT(e, rtol);
    // No step of the band ran: its warning (it "keeps them quasi-static and leaves that out")
    // does not stand.
    for (const std::string& w : run.result.warnings)
      EXPECT_EQ(w.find("band-limited run ("), std::string::npos) << w;
  }
}

// The band's quasi-static iteration on a bent beam: its Newton matrix is the tangent taken
// through the offsets' increment map (ModalExponential::update_tangent; the tangent alone took
// the rotation vectors' increments for rotations: at the tip, bent 0.057 rad, 4.8e4 N/rad of its
// bending stiffness in its twist, whose own is 4.5e3), where the evaluation began (the
// corrections made with K0 rolled back), and again where it stalls or grows. The cantilever above
// in a band of 30 Hz given (its two first bending modes): under 20 N the iteration diverged at
// t = 0 and auto ran dirk (0.02 s: 6.6 s); under 150 N it went 2,613 -> 573 -> 604 weights with
// the tangent where it began, under 200 N 1,299 -> 1,143 after it (a chord iteration gone stale),
// and auto ran dirk from t = 0 (2,334 and 2,360 steps). Now the band runs, off dirk's run at rtol
// 1e-9 by what its estimate says it leaves out (the dropped modes' ringing: under 20 N 0.014 of
// the tip's motion, 0.0132 measured; under 150 N 0.011, 0.0139 measured), and says so.
TEST(TransientAuto, AGivenBandRunsOnABentBeamAndMissesWhatItsEstimateSays) {
  for (const double force : {20.0, 150.0, 200.0}) {
    SCOPED_TRACE(force);
    const Model model = bent_cantilever(force);
    const double rtol = kBentRtol;
    const BandAgainstDirk runs = bent_cantilever_band(model);
    const TransientRun &reference = runs.reference, &run = runs.run;
    ASSERT_TRUE(reference.result.ok) << reference.result.message;
    ASSERT_TRUE(run.result.ok) << run.result.message;
    // Under 150 N the tip starts 0.4 rad from the equilibrium at t = 0: the band is linearized
    // again about the initial state.
    for (const MethodPhase& phase : run.result.phases)
      EXPECT_EQ(phase.method, "modal") << phase.reason;
    double estimate = 0.0;
    for (const std::string& w : run.result.warnings)
      if (w.find("band-limited run (30 Hz): the modes above the band would ring with about") == 0)
        estimate = std::stod(w.substr(w.find("about ") + 6));
    // The estimate is of the scene's own bodies (the tip), not of the segments' nodes.
    int tip = 0;
    while (tip < static_cast<int>(model.bodies.size()) && model.bodies[tip].name != "tip") ++tip;
    ASSERT_LT(tip, static_cast<int>(model.bodies.size()));
    const double e = motion_error(run, reference, tip);
    std::printf("%g N, band 30 Hz: %ld steps, the tip %.3g of its motion off (estimated %.3g)\n",
                force, run.result.stats.steps, e, estimate);
    EXPECT_LT(run.result.stats.steps, 100);
    EXPECT_GT(e, rtol);
    EXPECT_GT(estimate, 0.5 * e);
    EXPECT_LT(estimate, 2.0 * e);
  }
}

// The quasi-static modes' kinetic energy counts only where a step's change of them stands above
// the iteration's noise (kQuasiStaticNoiseMargin, core/analysis/modal_exponential.hpp). A 0.3 m
// cantilever of 20 mm square steel in 100 segments with a 0.2 kg tip under an 8 kN step (an
// adversarial review, 2026-12-03; a band of 27 kHz, 26 of 600 modes, chosen at rtol 1e-4): the
// largest |dy/dt|^2_M0 came from a step of 1.2e-11 s (6.7e9, where steps of 3e-6 s gave 1e-4
// against the band's 0.01 to 200), so the band was widened to every mode at 2.3 ms and the run
// warned of an error of 3e7 of the motion; over 0.03 s it took 53 s (dirk 28 s). Now the band
// runs on: 0.03 s in 9.1 s, 0.30 rtol off a dirk run at rtol 1e-6; here, 3 ms, 0.036 rtol off the
// modal method with every mode at rtol 1e-7 (not run here: 21 s).
TEST(TransientAuto, AStepsIterationNoiseIsNoInertiaOfTheQuasiStaticModes) {
  const Model model = scene_from_json(R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"sq": {"shape": "rectangle", "width": 0.02, "height": 0.02}},
    "bodies": [{"name": "tip", "mass": 0.2, "inertia": [1e-6, 1e-6, 1e-6],
                "position": [0.3, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [0.3, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq",
               "segments": 100}],
    "loads": [{"type": "force", "body": "tip", "value": [0, -8000, 2400],
               "time": {"type": "step", "at": 0.0}}]})");
  const double rtol = 1e-4;
  TransientOptions o = options(0.003, 2e-4, rtol, 1e-3 * rtol);
  o.integrator.method = IntegratorMethod::kAuto;
  const TransientRun run = simulate(model, o);
  ASSERT_TRUE(run.result.ok) << run.result.message;
  std::printf("%zu phases, %ld steps, band %.4g Hz\n", run.result.phases.size(),
              run.result.stats.steps, run.result.max_frequency_hz);
  ASSERT_EQ(run.result.phases.size(), 1u) << run.result.phases.back().reason;
  EXPECT_EQ(run.result.phases[0].method, "modal");
  EXPECT_GT(run.result.max_frequency_hz, 0.0);
  for (const std::string& w : run.result.warnings)
    EXPECT_EQ(w.find("band-limited run"), std::string::npos) << w;
}

// Beyond the dense solver's size the band comes from Lanczos: measured against a run of another
// method, the default DIRK table at a fixed step (L-stable: it damps the modes its step cannot
// resolve), whose own error is measured by halving that step.
TEST(TransientAuto, TheLanczosBandMeetsRtolAgainstAFixedStepImplicitRun) {
  const int bodies = kModalDenseBandMaxDofs / kDofsPerBody + 1;
  const Model model = scene_from_json(reference_cantilever(bodies));
  const double t_end = 0.01, output_step = 2e-4;
  TransientRun references[2];
  for (int k = 0; k < 2; ++k) {
    TransientOptions o = options(t_end, output_step, 1e-10, 1e-9);  // the Newton tolerance
    o.integrator.method = IntegratorMethod::kDirk;
    o.integrator.fixed_step = 5e-6 / (1 << k);
    references[k] = simulate(model, o);
    ASSERT_TRUE(references[k].result.ok) << references[k].result.message;
  }
  const TransientRun& reference = references[1];
  const double halving = run_error(model, references[0], reference);
  // The 5 us run is 4.6e-7 from the 2.5 us one (the 10 us run 1.5e-6 from the 5 us one: order
  // about 1.8); rtol 1e-6 would need a finer reference.
  for (double rtol : {1e-4, 1e-5}) {
    const TransientRun run = run_with(model, "auto", t_end, output_step, rtol);
    ASSERT_TRUE(run.result.ok) << run.result.message;
    ASSERT_EQ(run.result.phases.size(), 1u);
    EXPECT_NE(run.result.phases[0].reason.find("chosen for rtol"), std::string::npos)
        << run.result.phases[0].reason;
    const double e = run_error(model, run, reference);
    std::printf(
        "%d bodies, rtol %.0e: %s; error %.2e (%.2f rtol) against the fixed step 2.5 us, "
        "whose own error is below %.1e (the 5 us run's distance), %ld steps\n",
        bodies, rtol, run.result.phases[0].reason.c_str(), e, e / rtol, halving,
        run.result.stats.steps);
    // The reference's own error is about halving / 2.5 (order 1.8): this run's error is measured
    // within 10 %.
    EXPECT_LT(halving, 0.25 * e);
    // Within the issue's window, [1e-3, 10] rtol, and below 1.5 rtol (measured 0.45 and 0.38;
    // 0.54 and 0.71 when the quasi-static iteration stopped in the step's weights of the
    // centres, 3.0 and 2.9 when it stopped at 1e-3 of them).
    EXPECT_LT(e, 1.5 * rtol);
    EXPECT_GT(e, 1e-3 * rtol);
  }
  // At rtol 1e-7 no band of the kModalChosenBandMaxModes lowest modes meets rtol: every mode
  // (once bdf, 187k steps). This reference cannot measure its error (its own is about halving /
  // 2.5; the 2.5 us run is 1.33e-7 from this run's method at rtol 1e-10, and the 1.25 us run
  // 2.8e-8, docs/transient_measurements.md "Every mode where no band meets rtol"): within it.
  const TransientRun every = run_with(model, "auto", t_end, output_step, 1e-7);
  ASSERT_TRUE(every.result.ok) << every.result.message;
  ASSERT_EQ(every.result.phases.size(), 1u);
  EXPECT_NE(every.result.phases[0].reason.find("every mode integrated"), std::string::npos)
      << every.result.phases[0].reason;
  const double e = run_error(model, every, reference);
  std::printf("rtol 1e-7: every mode, %ld steps, %.2e from the fixed step 2.5 us\n",
              every.result.stats.steps, e);
  EXPECT_LT(e, halving);
}

// Band-limited runs (max_frequency_hz) on the reference cantilever in 10 segments against the
// full model's tight run: the error shrinks as the band widens, and a band above every mode is
// the full method.
TEST(TransientBand, ErrorShrinksAsTheBandWidens) {
  const Model model = scene_from_json(reference_cantilever(10));
  const TransientRun reference = tight(model, 0.1, 1e-3, 1e-12);
  ASSERT_TRUE(reference.result.ok) << reference.result.message;
  const TransientRun full = run_with(model, "modal", 0.1, 1e-3, 1e-7);
  ASSERT_TRUE(full.result.ok) << full.result.message;
  const double full_error = run_error(model, full, reference);
  std::printf("full model, rtol 1e-7: error %.2e, %ld steps\n", full_error,
              full.result.stats.steps);
  double previous = 1.0;
  for (double band : {20.0, 100.0, 500.0, 2000.0}) {
    const TransientRun run = run_with(model, "modal", 0.1, 1e-3, 1e-7, band);
    ASSERT_TRUE(run.result.ok) << band << " Hz: " << run.result.message;
    const double e = run_error(model, run, reference);
    std::printf("band %6.0f Hz, rtol 1e-7: error %.2e against the full model, %ld steps, %ld rhs\n",
                band, e, run.result.stats.steps, run.result.stats.rhs_evaluations);
    EXPECT_LT(e, 0.5 * previous) << band;
    // The modes above the band no longer hold the steps short.
    EXPECT_LT(run.result.stats.steps, full.result.stats.steps / 2) << band;
    previous = e;
  }
  EXPECT_LT(previous, 1e-4);
  // Above the highest mode: every mode integrated, the full method.
  const TransientRun all = run_with(model, "modal", 0.1, 1e-3, 1e-7, 1e9);
  ASSERT_TRUE(all.result.ok) << all.result.message;
  EXPECT_EQ(all.result.stats.steps, full.result.stats.steps);
  EXPECT_LT(run_error(model, all, full), 1e-9);
}

// The stiff-joint bob (tests/support/stiff_joint_bob.hpp) in a band of 20 Hz: its swing (0.9
// Hz) integrated, its joint's stiff modes (2.4e6 rad/s) quasi-static, against its closed form,
// wherever the scene sits. The quasi-static iteration once stopped in the step's error weights,
// rtol |c| + atol of the centres c: with the joint at the origin (the bob's centre 0.3 m below)
// it stopped within 3e-10 m across a joint of 6e12 N/m, and the run at rtol 1e-4, atol 1e-9 was
// 5.4e-6 m off (611 times rtol x + atol, x the swing of 78 um; 1.9e-6 with steps of 1 ms, 4.6e-7
// with 0.25 ms: first order in the step), silent; with the bob at the origin 3.3e-10 m. Now its
// weights are those of the motion (rtol x + atol, x the largest offset from the linearization):
// 0.0006, 0.04 and 0.03 times at rtol 1e-4 with the joint at the three places.
TEST(TransientBand, AQuasiStaticStiffJointIsSolvedWhereverTheSceneSits) {
  for (const std::array<double, 3> pivot :
       {std::array<double, 3>{0, 0, 0}, {0, 0.3, 0}, {100, 50, 0}}) {
    const Model model = scene_from_json(testing::stiff_joint_bob(pivot));
    const int bob = model.free_bodies.front();
    for (const auto& [rtol, atol] : {std::pair{1e-4, 1e-9}, std::pair{1e-6, 1e-8}}) {
      TransientOptions o = options(1.0, 0.005, rtol, atol);
      o.integrator.method = IntegratorMethod::kModal;
      o.integrator.max_frequency_hz = 20.0;
      const TransientRun run = simulate(model, o);
      ASSERT_TRUE(run.result.ok) << run.result.message;
      double error = 0.0, motion = 0.0;
      for (const testing::Snapshot& s : run.samples) {
        const double x = testing::stiff_joint_bob_x(s.sample.t);
        error = std::max(error, std::abs(s.c[bob].x() - pivot[0] - x));
        motion = std::max(motion, std::abs(x));
      }
      const double tolerance = rtol * motion + atol;
      std::printf(
          "joint at (%g, %g, %g), rtol %.0e: %.3g m off the closed form (%.3g times its "
          "tolerance), %ld steps, %ld evaluations\n",
          pivot[0], pivot[1], pivot[2], rtol, error, error / tolerance, run.result.stats.steps,
          run.result.stats.rhs_evaluations);
      EXPECT_LT(error, 0.1 * tolerance);
    }
  }
}

// A band chosen for rtol (max_frequency_hz "auto") over a run shorter than a quarter of the
// lowest period: what a load reaches by the end depends on when and how it acts. Each case on the
// reference cantilever in 40 segments against the full modal method at rtol 1e-10. Before (each
// case here), a step at 9 ms of a 10 ms run counted as if it acted from the start (27 modes, 15
// rtol), a load acting only after the run at its full static response (2 modes, 5e4 rtol), and
// ramps and a harmonic load over 1 ms at their static response (15 modes, 41 .. 122 rtol).
TEST(TransientBand, AChosenBandFollowsWhatTheLoadsDoWithinTheRun) {
  const std::string step = R"("time": {"type": "step", "at": 0.0})";
  struct Case {
    const char* label;
    const char* time;   // the tip load's time function
    const char* extra;  // another load, or ""
    double t_end, output_step, rtol;
  } cases[] = {
      {"step at 9 ms of 10 ms", R"("time": {"type": "step", "at": 0.009})", "", 0.01, 1e-4, 1e-4},
      {"step at 0 of 1 ms (the same motion)", R"("time": {"type": "step", "at": 0.0})", "", 1e-3,
       1e-5, 1e-4},
      {"ramp over 0.2 ms of 1 ms", R"("time": {"type": "ramp", "from": 0.0, "to": 2e-4})", "", 1e-3,
       1e-5, 1e-4},
      {"smooth ramp over 0.2 ms of 1 ms",
       R"("time": {"type": "smooth_ramp", "from": 0.0, "to": 2e-4})", "", 1e-3, 1e-5, 1e-4},
      {"300 Hz harmonic over 1 ms", R"("time": {"type": "harmonic", "frequency": 300})", "", 1e-3,
       1e-5, 1e-4},
      {"step at 0 and a 1 kN ramp from 10 s, over 1 ms", R"("time": {"type": "step", "at": 0.0})",
       R"(, {"type": "force", "body": "tip", "value": [0, 0, -1000],
             "time": {"type": "ramp", "from": 10, "to": 20}})",
       1e-3, 1e-5, 1e-4}};
  int modes_step_at_0 = 0;
  for (const Case& c : cases) {
    std::string json = reference_cantilever(40);
    json.replace(json.find(step), step.size(), c.time);
    json.replace(json.rfind("]}"), 2, std::string(c.extra) + "]}");
    const Model model = scene_from_json(json);
    TransientOptions o = options(c.t_end, c.output_step, 1e-10, 1e-14);
    o.integrator.method = IntegratorMethod::kModal;
    const TransientRun reference = simulate(model, o);
    ASSERT_TRUE(reference.result.ok) << c.label << ": " << reference.result.message;
    o.integrator.rtol = c.rtol;
    o.integrator.atol = 1e-2 * c.rtol;
    o.integrator.choose_band = true;
    const TransientRun run = simulate(model, o);
    ASSERT_TRUE(run.result.ok) << c.label << ": " << run.result.message;
    ASSERT_EQ(run.result.phases.size(), 1u);
    const std::string& why = run.result.phases[0].reason;
    int modes = 0;
    const size_t at = why.find("chosen for rtol: ");
    ASSERT_NE(at, std::string::npos) << why;
    ASSERT_EQ(std::sscanf(why.c_str() + at, "chosen for rtol: %d", &modes), 1) << why;
    const double e = run_error(model, run, reference);
    std::printf("%s, rtol %.0e: %d modes, error %.2e (%.2f rtol), %.2f s (reference %.2f s)\n",
                c.label, c.rtol, modes, e, e / c.rtol, run.result.stats.wall_seconds,
                reference.result.stats.wall_seconds);
    EXPECT_LT(e, 1.5 * c.rtol) << c.label;
    if (std::string(c.label).starts_with("step at 0 of")) modes_step_at_0 = modes;
    if (*c.extra) {
      EXPECT_EQ(modes, modes_step_at_0);  // a load acting after the run is not counted
    }
  }
}

}  // namespace
}  // namespace beamrail
