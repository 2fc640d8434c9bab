// The integrator families (CVODE bdf/adams, ARKODE dirk/erk, the modal exponential method), the
// linear solvers (dense, sparse KLU) and the Jacobian kinds (exact, finite differences) must all
// integrate the same motion: each is compared with a tight reference run on a segmented cantilever
// hit by a step load. Also: fixed steps converging at their table's order, the automatic choice of
// the linear solver, and the wall-clock budget ending a run as a timeout.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <string>

#include "tests/support/point_mass_tip.hpp"
#include "tests/support/reference_cantilever.hpp"
#include "tests/support/transient_run.hpp"

namespace beamrail {
namespace {

using testing::body_index;
using testing::motion_error;
using testing::options;
using testing::scene_from_json;
using testing::simulate;
using testing::Snapshot;
using testing::TransientRun;

using testing::reference_cantilever;

struct Family {
  const char* label;
  const char* method;
  const char* table;
  LinearSolverKind solver;
  JacobianKind jacobian;
  int max_order;
};

TEST(Integrators, EveryFamilyIntegratesTheSameMotion) {
  const Model model = scene_from_json(reference_cantilever(4));
  const int tip = body_index(model, "tip");
  ASSERT_GE(tip, 0);
  TransientOptions tight = options(0.05, 5e-4, 1e-11, 1e-12);
  const TransientRun reference = simulate(model, tight);
  ASSERT_TRUE(reference.result.ok) << reference.result.message;
  ASSERT_EQ(reference.samples.size(), 101u);

  const Family families[] = {
      {"bdf dense", "bdf", "", LinearSolverKind::kDense, JacobianKind::kExact, 5},
      {"bdf sparse", "bdf", "", LinearSolverKind::kSparse, JacobianKind::kExact, 5},
      {"bdf dense fd", "bdf", "", LinearSolverKind::kDense, JacobianKind::kFiniteDifference, 5},
      {"bdf order<=2", "bdf", "", LinearSolverKind::kAuto, JacobianKind::kExact, 2},
      {"adams", "adams", "", LinearSolverKind::kAuto, JacobianKind::kExact, 12},
      {"dirk default", "dirk", "", LinearSolverKind::kAuto, JacobianKind::kExact, 5},
      {"dirk TRBDF2", "dirk", "TRBDF2_3_3_2", LinearSolverKind::kAuto, JacobianKind::kExact, 5},
      {"dirk ESDIRK547", "dirk", "ESDIRK547L2SA2_7_4_5", LinearSolverKind::kDense,
       JacobianKind::kExact, 5},
      {"erk default", "erk", "", LinearSolverKind::kAuto, JacobianKind::kExact, 5},
      {"erk VERNER", "erk", "VERNER_8_5_6", LinearSolverKind::kAuto, JacobianKind::kExact, 5},
      {"modal", "modal", "", LinearSolverKind::kAuto, JacobianKind::kExact, 5},
  };
  for (const Family& f : families) {
    TransientOptions o = options(0.05, 5e-4, 1e-8, 1e-10);
    o.integrator.method = *method_from_name(f.method);
    o.integrator.table = f.table;
    o.integrator.linear_solver = f.solver;
    o.integrator.jacobian = f.jacobian;
    o.integrator.max_order = f.max_order;
    const TransientRun run = simulate(model, o);
    ASSERT_TRUE(run.result.ok) << f.label << ": " << run.result.message;
    ASSERT_EQ(run.samples.size(), reference.samples.size()) << f.label;
    const double e = motion_error(run, reference, tip);
    std::printf("%-16s error %.2e  steps %6ld  rhs %7ld  jac %5ld  solver %s\n", f.label, e,
                run.result.stats.steps, run.result.stats.rhs_evaluations,
                run.result.stats.jacobian_evaluations, run.result.linear_solver.c_str());
    // rtol 1e-8 on positions of about 1 m allows local errors near 1e-8 m against a tip motion
    // of about 1e-3 m: 1e-5 relative leaves room for error accumulation over the steps.
    EXPECT_LT(e, 1e-5) << f.label;
    if (std::string(f.method) == "modal") {
      EXPECT_EQ(run.result.linear_solver, "modal") << f.label;
      EXPECT_EQ(run.result.stats.jacobian_evaluations, 1) << f.label;
    } else if (std::string(f.method) == "erk") {
      EXPECT_EQ(run.result.linear_solver, "none") << f.label;
      EXPECT_EQ(run.result.stats.jacobian_evaluations, 0) << f.label;
    } else if (std::string(f.method) != "adams") {
      EXPECT_GT(run.result.stats.jacobian_evaluations, 0) << f.label;
    }
    if (f.solver == LinearSolverKind::kDense) {
      EXPECT_EQ(run.result.linear_solver, "dense");
    } else if (f.solver == LinearSolverKind::kSparse) {
      EXPECT_EQ(run.result.linear_solver, "sparse");
    }
  }
}

// fixed_step: every step has the given length (the step count is t_end / h) and the error falls
// at the table's order as h halves; the run warns that nothing estimated its error.
TEST(Integrators, FixedStepsTakeTheirLengthAndConvergeAtTheTablesOrder) {
  const Model model = scene_from_json(reference_cantilever(4));
  const int tip = body_index(model, "tip");
  const TransientRun reference = simulate(model, options(0.05, 5e-4, 1e-12, 1e-14));
  ASSERT_TRUE(reference.result.ok) << reference.result.message;
  struct Case {
    const char* method;
    const char* table;
    double order;  // the table's classical order
    double h0;     // the longest step
    int runs;
  };
  // The explicit table is stable up to about 5e-5 s here and within the reference's own error
  // (2e-12) by 2e-5 s: no range to measure its order in; one run against the reference.
  for (const Case c :
       {Case{"dirk", "", 5, 4e-4, 3}, Case{"dirk", "ARK437L2SA_DIRK_7_3_4", 4, 4e-4, 3},
        Case{"erk", "", 5, 3e-5, 1}}) {
    double previous = 0.0;
    for (int k = 0; k < c.runs; ++k) {
      const double h = c.h0 / std::pow(2.0, k);
      TransientOptions o = options(0.05, 5e-4, 1e-10, 1e-12);  // the Newton tolerance
      o.integrator.method = *method_from_name(c.method);
      o.integrator.table = c.table;
      o.integrator.fixed_step = h;
      const TransientRun run = simulate(model, o);
      ASSERT_TRUE(run.result.ok) << c.method << " " << c.table << ": " << run.result.message;
      EXPECT_NEAR(run.result.stats.steps, 0.05 / h, 1.0) << c.method << " " << c.table;
      ASSERT_EQ(run.result.warnings.size(), 1u);
      EXPECT_NE(run.result.warnings[0].find("fixed_step"), std::string::npos);
      const double e = motion_error(run, reference, tip);
      const double order = previous > 0.0 ? std::log2(previous / e) : 0.0;
      std::printf("%s %-22s h %.3e  steps %6ld  error %.3e  observed order %.2f\n", c.method,
                  c.table, h, run.result.stats.steps, e, order);
      if (previous > 0.0) {
        EXPECT_GT(order, c.order - 0.5) << c.method << " " << c.table;
      }
      if (c.runs == 1) {
        EXPECT_LT(e, 1e-10) << c.method;  // measured 1.0e-11
      }
      previous = e;
    }
  }
}

// An explicit table at a fixed step beyond its stability is refused before the run: nothing
// else would notice the fastest modes growing (a tip-body cantilever at 1 ms ended with 100 times
// its energy, status ok). The step the message names is stable: the run at it matches a tight
// run.
TEST(Integrators, AnUnstableExplicitFixedStepIsRefused) {
  const Model model = scene_from_json(reference_cantilever(4));
  const int tip = body_index(model, "tip");
  const TransientRun reference = simulate(model, options(0.05, 5e-4, 1e-12, 1e-14));
  ASSERT_TRUE(reference.result.ok) << reference.result.message;
  TransientOptions o = options(0.05, 5e-4, 1e-10, 1e-12);
  o.integrator.method = IntegratorMethod::kErk;
  o.integrator.fixed_step = 2e-4;
  const TransientRun refused = simulate(model, o);
  ASSERT_FALSE(refused.result.ok);
  const std::string& why = refused.result.message;
  const size_t at = why.find("a fixed step of at most ");
  ASSERT_NE(why.find("beyond the stability of the explicit table"), std::string::npos) << why;
  ASSERT_NE(at, std::string::npos) << why;
  const double stable = std::stod(why.substr(at + 24));
  std::printf("%s\n", why.c_str());
  EXPECT_LT(stable, 2e-4);
  EXPECT_GT(stable, 1e-5);
  o.integrator.fixed_step = stable;
  const TransientRun run = simulate(model, o);
  ASSERT_TRUE(run.result.ok) << run.result.message;
  const double e = motion_error(run, reference, tip);
  std::printf("at the step named, %.3g s: error %.2e against a tight run\n", stable, e);
  EXPECT_LT(e, 1e-6);
}

// An explicit run of a scene exactly at rest until a load's jump: nothing limits its steps
// there, and ARKODE's rows between them (Hermite interpolants of degree 5, which evaluate the
// forces at interpolated states) turned the interpolation's rounding into motion through the
// stiff forces: a flexible pendulum on the default joint wrote 7e-7 m and 5.18 J at rest. The
// steps now stay within explicit_longest_wh of the fastest mode (explicit_stability.hpp): the rows
// before the jump are the rest state, and the motion after it is a tight bdf run's. Here the
// joint is softer to keep the test short: without the bound Verner's rows moved the bodies by
// 7.2e-10 m with 5.4e-8 J, and Dormand-Prince's held 2.9e-15 J.
TEST(Integrators, AnExplicitRunsRowsAtRestStayAtRest) {
  const Model model = scene_from_json(R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"rod": {"shape": "circle", "diameter": 0.005}},
    "bodies": [{"name": "arm", "mass": 1, "inertia": [0.01, 0.01, 0.01], "position": [0.2, 0, 0]},
               {"name": "tip", "mass": 0.1, "inertia": [1e-5, 1e-5, 1e-5],
                "position": [0.6, 0, 0]}],
    "joints": [{"name": "hinge", "type": "revolute", "body1": "ground", "body2": "arm",
                "point": [0, 0, 0], "axis": [0, 0, 1], "relative_compliance": 1e-4}],
    "beams": [{"name": "rod", "body1": "arm", "body2": "tip", "point1": [0.2, 0, 0],
               "point2": [0.6, 0, 0], "point3": [0.2, 0, 1], "material": "steel",
               "section": "rod", "segments": 2}],
    "loads": [{"type": "force", "body": "tip", "value": [0, 1, 0],
               "time": {"type": "step", "at": 0.04}}]})");
  const int tip = body_index(model, "tip");
  TransientOptions o = options(0.045, 5e-4, 1e-11, 1e-13);
  const TransientRun reference = simulate(model, o);  // bdf
  ASSERT_TRUE(reference.result.ok) << reference.result.message;
  for (const char* table : {"VERNER_8_5_6", ""}) {
    o.integrator.method = IntegratorMethod::kErk;
    o.integrator.table = table;
    const TransientRun run = simulate(model, o);
    ASSERT_TRUE(run.result.ok) << run.result.message;
    double moved = 0.0, energy = 0.0;
    for (const Snapshot& s : run.samples) {
      if (s.sample.t >= 0.04) break;
      for (size_t i = 0; i < s.c.size(); ++i)
        moved = std::max(moved, (s.c[i] - run.samples[0].c[i]).norm());
      energy = std::max(energy, std::abs(s.sample.energy()));
    }
    const double e = motion_error(run, reference, tip);
    std::printf(
        "erk %s: %ld steps; before the jump the rows moved %.2e m with %.2e J; after, "
        "%.2e against bdf\n",
        *table ? table : "default", run.result.stats.steps, moved, energy, e);
    EXPECT_LT(moved, 1e-14);
    EXPECT_LT(energy, 1e-15);
    EXPECT_LT(e, 1e-7);
  }
}

// Runs dirk (the default table and ESDIRK547) at each rtol, atol = `base.integrator.atol` x rtol,
// with `base`'s span and outputs, and expects body `b` within rtol of its motion in `reference`.
// A reference run of a damped structure at rtol 1e-10, outputs every 1 ms: auto must run it
// with the modal method (each mode's damping exact).
void tight_modal_run(const Model& model, double t_end, double atol, TransientRun* run) {
  TransientOptions o = options(t_end, 1e-3, 1e-10, atol);
  o.integrator.method = IntegratorMethod::kAuto;
  *run = simulate(model, o);
  ASSERT_TRUE(run->result.ok) << run->result.message;
  ASSERT_EQ(run->result.phases.size(), 1u);
  ASSERT_EQ(run->result.phases[0].method, "modal");
}

void expect_dirk_within_rtol(const Model& model, const TransientRun& reference, int b,
                             const TransientOptions& base, std::initializer_list<double> rtols,
                             const char* label) {
  for (const char* table : {"", "ESDIRK547L2SA2_7_4_5"}) {
    for (double rtol : rtols) {
      TransientOptions o = options(base.t_end, base.output_step, rtol, base.integrator.atol * rtol);
      o.integrator.method = IntegratorMethod::kDirk;
      o.integrator.table = table;
      const TransientRun run = simulate(model, o);
      ASSERT_TRUE(run.result.ok) << run.result.message;
      const double e = motion_error(run, reference, b) / rtol;
      std::printf("%s, dirk %s, rtol %.0e: %.3g rtol of the motion, %ld steps\n", label,
                  *table ? table : "default", rtol, e, run.result.stats.steps);
      EXPECT_LT(e, 1.0);
    }
  }
}

// The implicit Runge-Kutta methods where a stiff mode rings against a slow motion: a 3 kg
// point-mass tip (rotary inertia 1e-6 kg m^2: a 5e5 rad/s rotary mode beside 13 rad/s bending) on
// a 1 m cantilever of 10 mm steel under a 1 N step. With each stage's derivative deduced from its
// Newton solution (ARKStepSetDeduceImplicitRhs, taken until 2026-11-29) the default table came
// out 4.3 / 25 / 52 / 19 rtol of the motion off at rtol 1e-4 / 1e-5 / 1e-6 / 1e-7, silent; the
// derivatives evaluated, 0.0026 / 0.014 / 0.025 / 0.083 (ESDIRK547 1.1 / 0.70 / 0.85 / 0.18 ->
// below 0.012). Since the steps end on the outputs (OutputsAreStepsNotInterpolants), 4.5e-6 /
// 1.5e-5 / 6.4e-5 / 0.040 (ESDIRK547 below 4.2e-4).
TEST(Integrators, ImplicitRungeKuttaFollowsRtolWhereAStiffModeRings) {
  const Model model = scene_from_json(testing::point_mass_tip(0.01, 1.0));
  const int tip = body_index(model, "tip");
  const TransientRun reference = testing::tight(model, 0.3, 1e-3);
  ASSERT_TRUE(reference.result.ok) << reference.result.message;
  expect_dirk_within_rtol(model, reference, tip, options(0.3, 1e-3, 1.0, 1e-3),
                          {1e-4, 1e-5, 1e-6, 1e-7}, "point-mass tip");
}

// The same methods on a damped beam: the reference cantilever in 10 segments with beam damping
// 1e-3 s (its fastest modes overdamped), 1 N step, 0.05 s, against a tight bdf run (which agrees
// with Verner at rtol 1e-11 to 1.9e-11 of the motion). An evaluated stage derivative carries the
// Newton iteration's error times the damped stiffness: at ARKODE's Newton coefficient 109 / 120
// rtol off at rtol 1e-4 / 1e-6 (ESDIRK547 21 / 0.31), silent; at a coefficient of 1e-4 0.26 /
// 0.33 (0.25 / 0.029), and 2.0e-5 / 8.9e-4 (1.2e-5 / 2.1e-4) since the steps end on the
// outputs; at kDampedNewtonCoefficient 1e-3 (2026-12-01) 4.9e-4 / 6.2e-4 (2.1e-4 / 1.7e-4).
TEST(Integrators, ImplicitRungeKuttaFollowsRtolOnADampedBeam) {
  std::string scene = reference_cantilever(10);
  const size_t at = scene.find(R"("segments": 10)");
  ASSERT_NE(at, std::string::npos);
  scene.insert(at, R"("damping": 0.001, )");
  const Model model = scene_from_json(scene);
  const int tip = body_index(model, "tip");
  const TransientRun reference = simulate(model, options(0.05, 5e-4, 1e-11, 1e-13));  // bdf
  ASSERT_TRUE(reference.result.ok) << reference.result.message;
  expect_dirk_within_rtol(model, reference, tip, options(0.05, 5e-4, 1.0, 1e-2), {1e-4, 1e-6},
                          "damped beam");
}

// A damped mechanism: a 1 kg bob 0.5 m below a stiff hinge (a cylindrical rail, a 50 mm steel axle
// of 20 mm diameter, damping 1e-4 s) swinging under gravity, 0.5 s, dirk at rtol 1e-4 / 1e-6
// (atol 1e-3 rtol), against bdf at rtol 1e-10. The tight Newton coefficient of damped scenes
// asks for more than ARKODE's three iterations where the modified Newton iteration converges
// slowly, and every shortfall was a failure, a new Jacobian and the stage again: 1,826 failures
// in 2,800 steps and 3,670 in 6,016 with three iterations; with kDampedNewtonIterations (five)
// 68 in 2,189 and 33 in 5,346 (0.093 -> 0.059 s and 0.19 -> 0.12 s) at 1.1e-5 / 3.3e-4 rtol of
// the motion (docs/transient_measurements.md "Five Newton iterations on damped scenes").
TEST(Integrators, ImplicitRungeKuttaOnADampedMechanismFailsFewNewtonIterations) {
  const Model model = scene_from_json(R"({
    "gravity": [0, 0, -9.81],
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"axle": {"shape": "circle", "diameter": 0.02}},
    "bodies": [{"name": "bob", "mass": 1.0, "inertia": [0.001, 0.001, 0.001],
                "position": [0.05, 0, -0.5], "velocity": [0, 3.0, 0],
                "angular_velocity": [6.0, 0, 0]}],
    "rails": [{"name": "hinge", "type": "cylindrical", "body1": "ground", "body2": "bob",
               "point1": [0, 0, 0], "point2": [0.05, 0, 0], "point3": [0, 1, 0],
               "material": "steel", "section": "axle", "damping": 1e-4}]})");
  const int bob = body_index(model, "bob");
  const TransientRun reference = simulate(model, options(0.5, 0.01, 1e-10, 1e-13));  // bdf
  ASSERT_TRUE(reference.result.ok) << reference.result.message;
  for (double rtol : {1e-4, 1e-6}) {
    TransientOptions o = options(0.5, 0.01, rtol, 1e-3 * rtol);
    o.integrator.method = IntegratorMethod::kDirk;
    const TransientRun run = simulate(model, o);
    ASSERT_TRUE(run.result.ok) << run.result.message;
    const double e = motion_error(run, reference, bob) / rtol;
    const SolverStats& st = run.result.stats;
    std::printf("damped hinge, dirk, rtol %.0e: %.3g rtol of the motion, %ld steps, %ld Newton "
                "failures, %ld Jacobians\n",
                rtol, e, st.steps, st.nonlinear_failures, st.jacobian_evaluations);
    EXPECT_LT(e, 1.0);
    EXPECT_LT(st.nonlinear_failures, st.steps / 10);
  }
}

// An overdamped stiff mode: the point-mass tip on a 1 m cantilever of 40 mm steel under a 1 kN
// step, the beam damped at 1e-3 s, so that the tip's 4e5 rad/s rotary mode decays at some 1.6e8
// 1/s. After the step the embedded estimates pass only at steps near that time constant: with
// ARKODE's 7 error test failures in a row every table but ARK437 failed ("the error test failed
// repeatedly, also at the smallest step": the default table at 0.020 / 0.013 / 0.0006 s at rtol
// 1e-4 / 1e-6 / 1e-8); with kDirkMaxErrorTestFailures (integrators.cpp) they run, against the
// modal method at rtol 1e-10 (each mode's damping exact; bdf at rtol 1e-10 agrees to 3e-9 of the
// motion) 0.014 / 0.16 / 0.45 of their tolerance (ESDIRK547 0.056 / 0.032 / 0.093); since the
// steps end on the outputs, 8.5e-5 / 0.0030 / 0.036 (4.4e-5 / 8.7e-4 / 0.0033); with the Newton
// coefficient 1e-3 (2026-12-01) 1.3e-4 / 0.0034 / 0.033 (3.6e-5 / 5.4e-4 / 0.0023).
TEST(Integrators, ImplicitRungeKuttaStepsThroughAnOverdampedMode) {
  const std::string scene = testing::point_mass_tip(0.04, 1000.0, 0.001);
  const Model model = scene_from_json(scene);
  const int tip = body_index(model, "tip");
  TransientRun reference;
  ASSERT_NO_FATAL_FAILURE(tight_modal_run(model, 0.3, 1e-14, &reference));
  expect_dirk_within_rtol(model, reference, tip, options(0.3, 1e-3, 1.0, 1e-4), {1e-4, 1e-6, 1e-8},
                          "overdamped point-mass tip");

  // The same cantilever on a shaker driven at 0.2 m/s, 20 Hz: auto runs dirk (a driven body),
  // and failed so at rtol 1e-4; now 0.0034 / 0.0090 rtol of its motion at rtol 1e-4 / 1e-6 against
  // bdf at rtol 1e-10 (5.2e-5 / 0.0031 since the steps end on the outputs).
  std::string shaken = scene;
  const std::string ground = R"("body1": "ground")";
  shaken.replace(shaken.find(ground), ground.size(), R"("body1": "shaker")");
  const std::string bodies = R"("bodies": [)";
  shaken.insert(shaken.find(bodies) + bodies.size(),
                R"({"name": "shaker", "position": [0, 0, 0], "motion": {"velocity": [0, 0.2, 0],
                    "velocity_time": {"type": "harmonic", "frequency": 20}}}, )");
  const Model driven = scene_from_json(shaken);
  const int driven_tip = body_index(driven, "tip");
  const TransientRun driven_reference = simulate(driven, options(0.3, 1e-3, 1e-10, 1e-14));
  ASSERT_TRUE(driven_reference.result.ok) << driven_reference.result.message;
  for (double rtol : {1e-4, 1e-6}) {
    TransientOptions o = options(0.3, 1e-3, rtol, 1e-4 * rtol);
    o.integrator.method = IntegratorMethod::kAuto;
    const TransientRun run = simulate(driven, o);
    ASSERT_TRUE(run.result.ok) << run.result.message;
    ASSERT_FALSE(run.result.phases.empty());
    EXPECT_EQ(run.result.phases[0].method.rfind("dirk", 0), 0u) << run.result.phases[0].method;
    const double e = motion_error(run, driven_reference, driven_tip) / rtol;
    std::printf("shaken point-mass tip, auto, rtol %.0e: %.3g rtol of the motion, %ld steps\n",
                rtol, e, run.result.stats.steps);
    EXPECT_LT(e, 1.0);
  }
}

// Where the motion is slow the steps grow far past the output spacing, and the SUNDIALS dense
// output between them is not error-controlled. The 10 mm point-mass tip on a steel cantilever of
// its own mass with beam damping 1e-2 s under a step of (0, -1, 0.3) N, 0.2 s, outputs every 1
// ms, against the modal method at rtol 1e-10: dirk's default table's interpolated outputs came
// out 3.8 / 18 / 17 rtol of the motion off at rtol 1e-4 / 1e-6 / 1e-8 (19 / 27 / 48 steps),
// silent; ending its steps on the outputs (integrators.cpp), 4e-9 / 4e-7 / 3e-5 (208 / 210 / 216
// steps). ESDIRK547 was within 0.5 there, and is within 4.4e-6 now; bdf at rtol 1e-4 / 1e-6 0.67
// / 1.3, now 1.8e-5 / 0.0029 (and 0.0045 at 1e-8), its steps ended on the outputs where they
// outgrew the spacing.
TEST(Integrators, OutputsAreStepsNotInterpolants) {
  const Model model = scene_from_json(testing::point_mass_tip(0.01, 1.0, 0.01, 0.3, 7850.0));
  const int tip = body_index(model, "tip");
  TransientRun reference;
  ASSERT_NO_FATAL_FAILURE(tight_modal_run(model, 0.2, 1e-15, &reference));
  // Each run must end at least one step on each of the 200 outputs.
  TransientOptions o = options(0.2, 1e-3, 1e-4, 1e-10);
  o.integrator.method = IntegratorMethod::kDirk;
  const TransientRun run = simulate(model, o);
  ASSERT_TRUE(run.result.ok) << run.result.message;
  EXPECT_GE(run.result.stats.steps, 200);
  expect_dirk_within_rtol(model, reference, tip, options(0.2, 1e-3, 1.0, 4e-7), {1e-4, 1e-6, 1e-8},
                          "damped point-mass tip, off-axis step");
  for (double rtol : {1e-4, 1e-6, 1e-8}) {
    TransientOptions m = options(0.2, 1e-3, rtol, 4e-7 * rtol);
    m.integrator.method = IntegratorMethod::kBdf;
    const TransientRun r = simulate(model, m);
    ASSERT_TRUE(r.result.ok) << r.result.message;
    const double e = motion_error(r, reference, tip) / rtol;
    std::printf(
        "damped point-mass tip, off-axis step, bdf, rtol %.0e: %.3g rtol of the motion, "
        "%ld steps\n",
        rtol, e, r.result.stats.steps);
    EXPECT_LT(e, 1.0);
  }
}

// A driven hub spins a 10 m beam (the spin-up of studies/spin_up.json, in 10 segments, up to
// 6 rad/s over 2 s, 3 s): auto runs dirk (a moving support). Its tip against a tight explicit run,
// in error weights rtol x 10 m: with the stage derivatives deduced 32 / 87 / 3.3 at rtol 1e-4 /
// 1e-5 / 1e-6, silent; now 0.05 / 0.22 / 0.13 (0.054 / 0.15 / 0.061 since the steps end on the
// outputs).
TEST(Integrators, ADrivenSpinUpFollowsRtol) {
  const Model model = scene_from_json(R"({
    "materials": {"rod": {"E": 2.8e7, "G": 1.0e7, "density": 1.2}},
    "sections": {"rod": {"shape": "custom", "S": 1.0, "Ix": 1e-3, "Iy": 5e-4, "Iz": 5e-4}},
    "bodies": [{"name": "hub", "position": [0, 0, 0],
                "motion": {"angular_velocity": [0, 0, 6],
                           "angular_velocity_time": {"type": "smooth_ramp", "from": 0, "to": 2}}},
               {"name": "tip", "position": [10, 0, 0]}],
    "beams": [{"name": "beam", "body1": "hub", "body2": "tip", "point1": [0, 0, 0],
               "point2": [10, 0, 0], "point3": [0, 1, 0], "material": "rod", "section": "rod",
               "segments": 10}]})");
  const int tip = body_index(model, "tip");
  const TransientRun reference = testing::tight(model, 3.0, 0.05);
  ASSERT_TRUE(reference.result.ok) << reference.result.message;
  for (double rtol : {1e-4, 1e-5, 1e-6}) {
    TransientOptions o = options(3.0, 0.05, rtol, 1e-9);
    o.integrator.method = IntegratorMethod::kAuto;
    const TransientRun run = simulate(model, o);
    ASSERT_TRUE(run.result.ok) << run.result.message;
    ASSERT_FALSE(run.result.phases.empty());
    EXPECT_EQ(run.result.phases[0].method, "dirk");
    const double weights = testing::body_deviation(run, reference, tip).error / (rtol * 10.0);
    std::printf("spin-up, auto (dirk), rtol %.0e: %.3g error weights, %ld steps\n", rtol, weights,
                run.result.stats.steps);
    EXPECT_LT(weights, 1.0);
  }
}

// A scene without elements has no elastic mode to bound an explicit run's steps by: the run goes
// on (the fastest mode's eigenproblem, on a zero stiffness, failed the run at once before).
// A free body moves on at its velocity.
TEST(Integrators, AnExplicitRunOfBodiesWithoutElementsRuns) {
  const Model model = scene_from_json(R"({
    "bodies": [{"name": "a", "mass": 1.0, "inertia": [0.01, 0.02, 0.03], "position": [0, 0, 0],
                "angular_velocity": [1, 2, 3]},
               {"name": "b", "mass": 1.0, "inertia": [0.01, 0.01, 0.01], "position": [0.3, 0, 0],
                "velocity": [0, 1, 0]}]})");
  const int b = body_index(model, "b");
  for (const char* table : {"", "VERNER_8_5_6"}) {
    TransientOptions o = options(0.5, 0.01, 1e-6, 1e-8);
    o.integrator.method = IntegratorMethod::kErk;
    o.integrator.table = table;
    const TransientRun run = simulate(model, o);
    ASSERT_TRUE(run.result.ok) << run.result.message;
    const Vec3 end = run.samples.back().c[b];
    EXPECT_NEAR(end.x(), 0.3, 1e-12);
    EXPECT_NEAR(end.y(), 0.5, 1e-12);
  }
}

// Dense LU and sparse KLU solve the same Newton systems: the runs differ only by rounding.
TEST(Integrators, DenseAndSparseSolversGiveTheSameRun) {
  const Model model = scene_from_json(reference_cantilever(6));
  const int tip = body_index(model, "tip");
  TransientOptions o = options(0.02, 1e-3, 1e-7, 1e-10);
  o.integrator.linear_solver = LinearSolverKind::kDense;
  const TransientRun dense = simulate(model, o);
  o.integrator.linear_solver = LinearSolverKind::kSparse;
  const TransientRun sparse = simulate(model, o);
  ASSERT_TRUE(dense.result.ok && sparse.result.ok);
  EXPECT_EQ(sparse.result.linear_solver, "sparse");
  // 6 bodies: 78 states; each body's 13x13 block couples only to its chain neighbours.
  EXPECT_GT(sparse.result.jacobian_nonzeros, 0);
  EXPECT_LT(sparse.result.jacobian_nonzeros, 78 * 78 / 2);
  const double e = motion_error(sparse, dense, tip);
  std::printf("dense vs sparse: %.2e relative, steps %ld vs %ld, nonzeros %ld\n", e,
              dense.result.stats.steps, sparse.result.stats.steps, sparse.result.jacobian_nonzeros);
  // Both runs meet the same tolerances; rounding differences in the factorizations can change
  // step sizes, so they agree to the integration accuracy (rtol 1e-7 on positions of about 1 m
  // against a motion of about 1e-4 m), not bitwise.
  EXPECT_LT(e, 1e-6);
}

TEST(Integrators, AutomaticLinearSolverSwitchesToSparseAtTheMeasuredSize) {
  TransientOptions o = options(1e-3, 1e-3, 1e-6, 1e-9);
  const Model one = scene_from_json(reference_cantilever(1));  // 13 states
  const Model two = scene_from_json(reference_cantilever(2));  // 26 states
  ASSERT_EQ(one.n_states, 13);
  ASSERT_EQ(two.n_states, 26);
  ASSERT_GE(two.n_states, kSparseStateThreshold);
  ASSERT_LT(one.n_states, kSparseStateThreshold);
  EXPECT_EQ(simulate(one, o).result.linear_solver, "dense");
  EXPECT_EQ(simulate(two, o).result.linear_solver, "sparse");
}

TEST(Integrators, WallClockBudgetEndsARunAsATimeoutAndKeepsItsSamples) {
  const Model model = scene_from_json(reference_cantilever(10));
  TransientOptions o = options(100.0, 1e-3, 1e-10, 1e-12);  // hours of work at this tolerance
  o.max_seconds = 0.2;
  const TransientRun run = simulate(model, o);
  EXPECT_FALSE(run.result.ok);
  EXPECT_TRUE(run.result.timed_out);
  EXPECT_NE(run.result.message.find("timeout"), std::string::npos) << run.result.message;
  EXPECT_GT(run.result.t_reached, 0.0);
  EXPECT_LT(run.result.t_reached, 100.0);
  // Every output time reached was delivered, and nothing beyond.
  ASSERT_GE(run.samples.size(), 1u);
  EXPECT_LE(run.samples.back().sample.t, run.result.t_reached + 1e-12);
  EXPECT_GE(run.result.stats.wall_seconds, 0.2);
  std::printf("budget 0.2 s: stopped after %.3f s at t = %.4f s with %zu samples\n",
              run.result.stats.wall_seconds, run.result.t_reached, run.samples.size());
}

}  // namespace
}  // namespace beamrail
