// The modal (exponential) integrator: its phi functions against closed forms, exactness on a
// linear motion, agreement with a tight reference on planar and 3-D motions and across load
// breakpoints, its observed order of convergence, and its limits (scene size, large rotations).
#include "core/analysis/modal_integrator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "core/analysis/dense_product.hpp"
#include "core/analysis/exponential_step.hpp"
#include "tests/support/reference_cantilever.hpp"
#include "tests/support/transient_run.hpp"

namespace beamrail {
namespace {

using testing::body_index;
using testing::motion_error;
using testing::options;
using testing::reference_cantilever;
using testing::scene_from_json;
using testing::simulate;
using testing::TransientRun;

TransientOptions modal(double t_end, double output_step, double rtol, double atol) {
  TransientOptions o = options(t_end, output_step, rtol, atol);
  o.integrator.method = IntegratorMethod::kModal;
  return o;
}

// The tight run a modal run is compared with: ERK (Verner 8(7)) at rtol / atol.
TransientRun tight_reference(const Model& model, double t_end, double output_step, double rtol,
                             double atol) {
  TransientOptions o = options(t_end, output_step, rtol, atol);
  o.integrator.method = IntegratorMethod::kErk;
  o.integrator.table = "VERNER_8_5_6";
  return simulate(model, o);
}

TEST(ModalIntegrator, OscillatorFunctionsMatchTheirClosedForms) {
  // g_m(x) = sum_j (-x)^j / (2j+m)!; with s = sqrt(x): g0 = cos s, g1 = sin s / s,
  // g2 = (1 - cos s) / x, g3 = (s - sin s) / s^3, g4 = (x/2 - 1 + cos s) / x^2 (cosh, sinh for
  // x < 0). Closed forms in long double away from 0, the series in long double near it.
  double worst = 0.0;
  for (double x : {-400.0, -30.0, -4.5, -3.9, -0.7, -1e-9, 0.0, 1e-12, 1e-3, 0.5, 3.99, 4.01, 17.0,
                   250.0, 1e4, 3.3e7}) {
    const std::array<double, 5> g = oscillator_g(x);
    long double ref[5];
    if (std::abs(x) > 2.0) {
      const long double xl = x, s = std::sqrt(std::abs(xl));
      const long double c = x > 0 ? std::cos(s) : std::cosh(s);
      const long double sn = x > 0 ? std::sin(s) : std::sinh(s);
      ref[0] = c;
      ref[1] = sn / s;
      ref[2] = (1 - c) / xl;
      ref[3] = x > 0 ? (s - sn) / (s * s * s) : (sn - s) / (s * s * s);
      ref[4] = (xl / 2 - 1 + c) / (xl * xl);
    } else {
      for (int m = 0; m < 5; ++m) {
        long double fact = 1, sum = 0, term;
        for (int i = 2; i <= m; ++i) fact *= i;
        term = 1 / fact;
        for (int j = 0; j < 40; ++j) {
          sum += term;
          term *= -static_cast<long double>(x) / ((2 * j + m + 1) * (2 * j + m + 2));
        }
        ref[m] = sum;
      }
    }
    for (int m = 0; m < 5; ++m) {
      // Relative to the size of the terms (g0, g1 oscillate through zero for large x). Rounding
      // x to double moves s = sqrt(x) by eps s / 2, hence cos s by up to that much: the bound
      // grows with s.
      const double scale = m < 2 ? std::max(1.0, std::abs(static_cast<double>(ref[m])))
                                 : std::abs(static_cast<double>(ref[m]));
      const double e = std::abs(g[m] - static_cast<double>(ref[m])) / scale;
      const double s = std::sqrt(std::abs(x));
      worst = std::max(worst, e / (1.0 + s));
      EXPECT_LT(e, 1e-13 * (1.0 + s)) << "x " << x << " m " << m;
    }
  }
  std::printf("oscillator phi functions: worst relative error / (1 + sqrt|x|) %.1e\n", worst);
}

// A point mass on a massless beam pulled along the beam's axis: the motion stays on the axis, the
// beam force is linear in the stretch, and the response to the step load is the closed form
// x(t) = F/k (1 - cos w t). The integrator treats the linear part exactly, so the error is
// rounding, whatever the step.
TEST(ModalIntegrator, AxialStepResponseIsExact) {
  const Model model = scene_from_json(R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [{"name": "m", "position": [1, 0, 0], "mass": 2.0,
                "inertia": [0.01, 0.01, 0.01]}],
    "beams": [{"name": "b", "body1": "ground", "body2": "m", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq"}],
    "loads": [{"type": "force", "body": "m", "value": [100, 0, 0],
               "time": {"type": "step", "at": 0.0}}]})");
  const int m = body_index(model, "m");
  const double k = 2.1e11 * 1e-4 / 1.0, w = std::sqrt(k / 2.0), amplitude = 100.0 / k;
  const TransientRun run = simulate(model, modal(0.01, 1e-4, 1e-8, 1e-12));
  ASSERT_TRUE(run.result.ok) << run.result.message;
  double worst = 0.0;
  for (const auto& s : run.samples) {
    const double exact = amplitude * (1.0 - std::cos(w * s.sample.t));
    worst = std::max(worst, std::abs(s.c[m].x() - 1.0 - exact));
    EXPECT_LT(s.c[m].tail<2>().norm(), 1e-20);
  }
  std::printf(
      "axial step: worst error %.2e of amplitude %.2e (w = %.0f rad/s, %.1f periods), "
      "%ld steps for %zu outputs\n",
      worst, amplitude, w, w * 0.01 / (2 * M_PI), run.result.stats.steps, run.samples.size() - 1);
  // Positions near 1 m: rounding of c is 1.1e-16; a few ulps over 100 outputs.
  EXPECT_LT(worst, 1e-14);
  // Steps as long as the outputs allow (one per output interval).
  EXPECT_LE(run.result.stats.steps, static_cast<long>(run.samples.size() - 1));
  EXPECT_EQ(run.result.linear_solver, "modal");
  EXPECT_EQ(run.result.stats.jacobian_evaluations, 1);
}

// The reference cantilever (planar bending) and a 3-D variant (oblique tip load and a tip torque:
// bending in two planes plus torsion, so the rotation-vector kinematics are exercised) against
// tight ERK runs.
TEST(ModalIntegrator, AgreesWithATightReference) {
  std::string three_d = reference_cantilever(6);
  const std::string planar_load = R"("value": [0, -1, 0])";
  three_d.replace(three_d.find(planar_load), planar_load.size(), R"("value": [0, -1, 0.7])");
  three_d.replace(three_d.rfind("]}"), 2,
                  R"(, {"type": "torque", "body": "tip", "value": [0.3, 0, 0],
                       "time": {"type": "step", "at": 0.0}}]})");
  struct Case {
    const char* label;
    std::string json;
  } cases[] = {{"planar, 6 segments", reference_cantilever(6)}, {"3-D, 6 segments", three_d}};
  for (const Case& c : cases) {
    const Model model = scene_from_json(c.json);
    const int tip = body_index(model, "tip");
    const TransientRun reference = tight_reference(model, 0.05, 5e-4, 1e-11, 1e-12);
    ASSERT_TRUE(reference.result.ok) << reference.result.message;
    for (double rtol : {1e-6, 1e-7}) {
      const TransientRun run = simulate(model, modal(0.05, 5e-4, rtol, 1e-2 * rtol));
      ASSERT_TRUE(run.result.ok) << c.label << ": " << run.result.message;
      ASSERT_EQ(run.samples.size(), reference.samples.size()) << c.label;
      const double e = motion_error(run, reference, tip);
      // Largest angle between the tip body's orientations.
      double angle = 0.0;
      for (size_t k = 0; k < run.samples.size(); ++k) {
        const Mat3 d = run.samples[k].pose[tip].A * reference.samples[k].pose[tip].A.transpose();
        angle = std::max(angle, rotation_vector(d).norm());
      }
      std::printf("%-20s rtol %.0e: tip error %.2e, orientation %.1e rad, steps %ld, rhs %ld\n",
                  c.label, rtol, e, angle, run.result.stats.steps,
                  run.result.stats.rhs_evaluations);
      // The error per unit tolerance stays below 1 (the embedded second-order estimate is
      // conservative).
      EXPECT_LT(e, rtol) << c.label;
      EXPECT_LT(angle, 1e-2 * rtol) << c.label;
    }
  }
}

// A run given two threads for its products (a single run of the command line) takes the same
// steps to the same states, to the bit, as on one: every entry of a product is summed in the
// same order. On one thread a stage's projection and the next stage's change of basis share one
// pass over Phi (multiply_transposed_then); on two they are two passes, each shared. The
// reference cantilever in 100 segments: a 600 x 600 basis, above the size from which the products
// use threads.
TEST(ModalIntegrator, TwoThreadsGiveTheSameRunToTheBit) {
  const Model model = scene_from_json(reference_cantilever(100));
  ASSERT_GE(model.n_dofs * model.n_dofs, kParallelProductSize);
  const TransientRun one = simulate(model, modal(0.002, 5e-4, 1e-6, 1e-8));
  TransientRun two;
  const long shared_before = products_on_threads();
  {
    const ProductThreads threads(2);
    two = simulate(model, modal(0.002, 5e-4, 1e-6, 1e-8));
  }
  // Every product of the run's steps was shared (about ten a step).
  EXPECT_GT(products_on_threads() - shared_before, 10 * two.result.stats.steps);
  EXPECT_EQ(product_threads(), 1);  // restored
  ASSERT_TRUE(one.result.ok && two.result.ok) << one.result.message << two.result.message;
  EXPECT_GT(one.result.stats.steps, 10);
  EXPECT_EQ(one.result.stats.steps, two.result.stats.steps);
  EXPECT_EQ(one.result.stats.rhs_evaluations, two.result.stats.rhs_evaluations);
  ASSERT_EQ(one.samples.size(), two.samples.size());
  for (size_t k = 0; k < one.samples.size(); ++k)
    for (int b : model.free_bodies) {
      EXPECT_EQ(one.samples[k].c[b], two.samples[k].c[b]) << "sample " << k << " body " << b;
      EXPECT_EQ(one.samples[k].q[b], two.samples[k].q[b]) << "sample " << k << " body " << b;
    }
}

// A step load makes the structure vibrate about its loaded equilibrium: linearized there
// ("about": "static", the default) the nonlinear remainder is smaller than about the unloaded
// initial state: at the same fixed step the error is smaller, and at the same tolerance (errors
// follow rtol) it takes fewer steps. Both agree with a tight reference.
TEST(ModalIntegrator, LinearizesAboutTheLoadedEquilibrium) {
  const Model model = scene_from_json(reference_cantilever(10));
  const int tip = body_index(model, "tip");
  const TransientRun reference = tight_reference(model, 0.05, 5e-4, 1e-11, 1e-12);
  ASSERT_TRUE(reference.result.ok) << reference.result.message;
  long steps[2] = {0, 0};
  double error[2] = {0.0, 0.0}, fixed_error[2] = {0.0, 0.0};
  const char* about[2] = {"static", "initial"};
  for (int i = 0; i < 2; ++i) {
    TransientOptions o = modal(0.05, 5e-4, 1e-6, 1e-8);
    o.integrator.about = about[i];
    const TransientRun run = simulate(model, o);
    ASSERT_TRUE(run.result.ok) << about[i] << ": " << run.result.message;
    EXPECT_TRUE(run.result.warnings.empty()) << about[i];
    error[i] = motion_error(run, reference, tip);
    steps[i] = run.result.stats.steps;
    // Fixed steps of 1e-4 s (a tolerance that never rejects).
    o = modal(0.05, 5e-4, 1e3, 1e3);
    o.integrator.about = about[i];
    o.integrator.max_step = o.integrator.initial_step = 1e-4;
    const TransientRun fixed = simulate(model, o);
    ASSERT_TRUE(fixed.result.ok) << about[i] << ": " << fixed.result.message;
    fixed_error[i] = motion_error(fixed, reference, tip);
    std::printf("about %-7s: rtol 1e-6: tip error %.2e, steps %ld; fixed step 1e-4 s: %.2e\n",
                about[i], error[i], steps[i], fixed_error[i]);
    EXPECT_LT(error[i], 1e-6) << about[i];
  }
  EXPECT_LT(steps[0], steps[1]);
  EXPECT_LT(fixed_error[0], fixed_error[1]);
}

// A free body pushed by a constant force has no equilibrium: asked for one, the run fails saying
// so; by default it linearizes about the initial state with a warning that says why in the run's
// terms (not the static search's: the load factor it reached), and the motion is the closed form
// x = F t^2 / 2m (the rigid modes have lambda = 0: the force is integrated exactly). auto takes
// the initial state as its choice: the reason says why, and no warning.
TEST(ModalIntegrator, FallsBackToTheInitialStateWithoutAnEquilibrium) {
  const Model model = scene_from_json(R"({
    "bodies": [{"name": "puck", "position": [0, 0, 0], "mass": 2.0, "inertia": [0.1, 0.1, 0.1]}],
    "loads": [{"type": "force", "body": "puck", "value": [3, 0, 0],
               "time": {"type": "step", "at": 0.0}}]})");
  TransientOptions o = modal(0.1, 0.01, 1e-8, 1e-10);
  o.integrator.about = "static";
  const TransientRun strict = simulate(model, o);
  EXPECT_FALSE(strict.result.ok);
  EXPECT_NE(strict.result.message.find("push along a direction without stiffness (a free body "
                                       "or mechanism, such as a carriage driven along its rail): "
                                       "no static equilibrium exists"),
            std::string::npos)
      << strict.result.message;
  o.integrator.about = "";
  const TransientRun run = simulate(model, o);
  ASSERT_TRUE(run.result.ok) << run.result.message;
  ASSERT_EQ(run.result.warnings.size(), 1u);
  const std::string why =
      "linearized about the initial state: the loads at t = 0 push along a direction without "
      "stiffness";
  EXPECT_NE(run.result.warnings[0].find(why), std::string::npos) << run.result.warnings[0];
  EXPECT_EQ(run.result.warnings[0].find("load factor"), std::string::npos)
      << run.result.warnings[0];
  const int b = body_index(model, "puck");
  ASSERT_EQ(run.samples.size(), 11u);
  for (const auto& s : run.samples)
    EXPECT_NEAR(s.c[b].x(), 0.75 * s.sample.t * s.sample.t, 1e-14) << s.sample.t;

  o.integrator.method = IntegratorMethod::kAuto;
  const TransientRun chosen = simulate(model, o);
  ASSERT_TRUE(chosen.result.ok) << chosen.result.message;
  EXPECT_TRUE(chosen.result.warnings.empty()) << chosen.result.warnings[0];
  ASSERT_FALSE(chosen.result.phases.empty());
  EXPECT_EQ(chosen.result.phases[0].method, "modal");
  EXPECT_NE(chosen.result.phases[0].reason.find(why), std::string::npos)
      << chosen.result.phases[0].reason;
  ASSERT_EQ(chosen.samples.size(), 11u);
  for (const auto& s : chosen.samples)
    EXPECT_NEAR(s.c[b].x(), 0.75 * s.sample.t * s.sample.t, 1e-14) << s.sample.t;
}

// A tip torque that bends the cantilever's equilibrium 1.5 rad (EI = 175 N m^2): too far to
// linearize about; by default the run linearizes about the initial state and warns. (A torque
// that twisted it 1.5 rad served once; about the axis of a square shaft a torque of fixed
// direction makes it flutter (Ziegler), and the static equilibrium is refused as unstable.)
TEST(ModalIntegrator, DoesNotLinearizeAboutAFarEquilibrium) {
  std::string json = reference_cantilever(1);
  const std::string force = R"("type": "force", "body": "tip", "value": [0, -1, 0])";
  json.replace(json.find(force), force.size(),
               R"("type": "torque", "body": "tip", "value": [0, 0, 262.5])");
  const Model model = scene_from_json(json);
  TransientOptions o = modal(1e-4, 1e-5, 1e-6, 1e-8);
  o.integrator.about = "static";
  const TransientRun strict = simulate(model, o);
  EXPECT_FALSE(strict.result.ok);
  EXPECT_NE(strict.result.message.find("body \"tip\" is turned more than 1 rad"), std::string::npos)
      << strict.result.message;
  o.integrator.about = "";
  const TransientRun run = simulate(model, o);
  ASSERT_TRUE(run.result.ok) << run.result.message;
  ASSERT_EQ(run.result.warnings.size(), 1u);
  EXPECT_NE(run.result.warnings[0].find("linearized about the initial state: in the static "
                                        "equilibrium under the loads at t = 0, body \"tip\""),
            std::string::npos)
      << run.result.warnings[0];
  EXPECT_NE(run.result.warnings[0].find("the run stops if a body turns more than 1 rad"),
            std::string::npos)
      << run.result.warnings[0];
  // auto linearizes again as the bodies turn: its run does not stop there, and says so.
  o.integrator.method = IntegratorMethod::kAuto;
  const TransientRun relinearized = simulate(model, o);
  ASSERT_TRUE(relinearized.result.ok) << relinearized.result.message;
  ASSERT_FALSE(relinearized.result.warnings.empty());
  EXPECT_NE(relinearized.result.warnings[0].find("(auto linearizes again as the bodies turn)"),
            std::string::npos)
      << relinearized.result.warnings[0];
  EXPECT_EQ(relinearized.result.warnings[0].find("the run stops"), std::string::npos);
}

TEST(ModalIntegrator, RestartsAtLoadBreakpoints) {
  // A triangular tip pulse (0 -> 1 N at 5 ms -> 0 at 10 ms): two restarts, then free vibration.
  std::string json = reference_cantilever(4);
  const std::string step = R"({"type": "step", "at": 0.0})";
  json.replace(json.find(step), step.size(),
               R"({"type": "table", "t": [0, 0.005, 0.01], "v": [0, 1, 0]})");
  const Model model = scene_from_json(json);
  const int tip = body_index(model, "tip");
  const TransientRun reference = tight_reference(model, 0.04, 5e-4, 1e-11, 1e-12);
  const TransientRun run = simulate(model, modal(0.04, 5e-4, 1e-7, 1e-9));
  ASSERT_TRUE(reference.result.ok && run.result.ok) << run.result.message;
  ASSERT_EQ(run.samples.size(), reference.samples.size());
  const double e = motion_error(run, reference, tip);
  std::printf("pulse with two breakpoints: tip error %.2e, steps %ld\n", e, run.result.stats.steps);
  EXPECT_LT(e, 1e-7);
}

// Fixed steps (a tolerance that never rejects) halved three times on the reference cantilever in
// 4 segments: the observed order of the error in the tip motion. (From 2026-12-02 01:06 to the
// same day's edge bounds the steps started at 2.5e-4 s, below a bound that resolved the modes
// carrying 99 % of the motion and held the steps of 1e-3 and 5e-4 s alike; each run's steps are
// asserted, so no bound can hold them unseen.)
TEST(ModalIntegrator, ObservedOrderOfConvergence) {
  const Model model = scene_from_json(reference_cantilever(4));
  const int tip = body_index(model, "tip");
  const TransientRun reference = tight_reference(model, 0.05, 1e-3, 1e-12, 1e-13);
  ASSERT_TRUE(reference.result.ok);
  double previous = 0.0;
  double lowest_order = 10.0;
  for (double h : {1e-3, 5e-4, 2.5e-4, 1.25e-4}) {
    TransientOptions o = modal(0.05, 1e-3, 1e3, 1e3);
    o.integrator.max_step = h;
    o.integrator.initial_step = h;
    const TransientRun run = simulate(model, o);
    ASSERT_TRUE(run.result.ok) << run.result.message;
    ASSERT_EQ(run.samples.size(), reference.samples.size());
    EXPECT_EQ(run.result.stats.steps, std::lround(0.05 / h)) << h;
    const double e = motion_error(run, reference, tip);
    if (previous > 0.0) {
      const double order = std::log2(previous / e);
      lowest_order = std::min(lowest_order, order);
      std::printf("h %.3e: error %.3e, observed order %.2f, %ld steps\n", h, e, order,
                  run.result.stats.steps);
    } else {
      std::printf("h %.3e: error %.3e, %ld steps\n", h, e, run.result.stats.steps);
    }
    previous = e;
  }
  // Order 4 for smooth nonlinearities; the rotation of the beams' stiffness with the (small)
  // deflection about the equilibrium couples the fast modes into the nonlinear part, and the
  // observed order drops.
  EXPECT_GT(lowest_order, 2.0);
}

TEST(ModalIntegrator, RefusesScenesAboveItsSizeLimit) {
  const int too_many = kModalIntegratorMaxDofs / kDofsPerBody + 1;
  const Model model = scene_from_json(reference_cantilever(too_many));
  ASSERT_GT(model.n_dofs, kModalIntegratorMaxDofs);
  const TransientRun run = simulate(model, modal(1e-3, 1e-3, 1e-6, 1e-9));
  EXPECT_FALSE(run.result.ok);
  EXPECT_NE(run.result.message.find("up to 400 free bodies"), std::string::npos)
      << run.result.message;
  EXPECT_TRUE(run.samples.empty());
}

TEST(ModalIntegrator, StopsWithAMessageWhenABodyTurnsTooFar) {
  // A body spinning at 2.2 rad/s about z on a revolute joint to the ground at its centre passes
  // 1 rad after 0.45 s (a free one floats: the method follows it in a turning frame,
  // turning_frame_test.cpp).
  const Model model = scene_from_json(R"({
    "bodies": [{"name": "spinner", "position": [0, 0, 0], "mass": 1.0,
                "inertia": [0.1, 0.1, 0.2], "angular_velocity": [0, 0, 2.2]}],
    "joints": [{"name": "pin", "type": "revolute", "body1": "ground", "body2": "spinner",
                "point": [0, 0, 0], "axis": [0, 0, 1]}]})");
  const TransientRun run = simulate(model, modal(1.0, 0.1, 1e-8, 1e-10));
  EXPECT_FALSE(run.result.ok);
  EXPECT_NE(run.result.message.find("\"spinner\" turned more than"), std::string::npos)
      << run.result.message;
  // The samples up to 0.4 s (0.88 rad) are delivered and exact: a free rotation about a
  // principal axis is the closed form angle = 2.2 t.
  ASSERT_EQ(run.samples.size(), 5u);
  const int b = body_index(model, "spinner");
  for (const auto& s : run.samples)
    EXPECT_NEAR(rotation_vector(s.pose[b].A).z(), 2.2 * s.sample.t, 1e-12) << s.sample.t;
  // It stops at its last accepted step within the limit: from the last sample on, before 1 rad
  // (where that step ends depends on the step sizes: a mechanism's are bounded while its stiff
  // modes hold energy, kMechanismStep in modal_step_bounds.hpp).
  EXPECT_GE(run.result.t_reached, 0.4);
  EXPECT_LT(run.result.t_reached, 1.0 / 2.2);
}

}  // namespace
}  // namespace beamrail
