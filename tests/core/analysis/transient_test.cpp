// Transient analysis against closed forms and conservation laws (docs/model.md "Validation").
#include "core/analysis/transient.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <string>

#include "tests/support/transient_run.hpp"

namespace beamrail {
namespace {

using testing::Snapshot;
using testing::TransientRun;
constexpr double kPi = std::numbers::pi;

// Steel, 1 m, 10 mm square section (the paper's kind of test piece).
constexpr double kE = 2.1e11, kG = 8.0769e10, kL = 1.0, kSide = 0.01;
const double kArea = kSide * kSide;
const double kI = std::pow(kSide, 4) / 12.0;

// Cantilever from ground to a tip body at (1, 0, 0); the body's JSON fields are spliced in.
std::string cantilever(const std::string& tip_fields, const std::string& beam_fields = "") {
  return R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [{"name": "tip", "position": [1, 0, 0], )" +
         tip_fields + R"(}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq" )" +
         beam_fields + "}]}";
}

// Mean spacing of the upward zero crossings of signal(snapshot), by linear interpolation.
double period(const TransientRun& run, const std::function<double(const Snapshot&)>& signal) {
  std::vector<double> crossings;
  for (size_t k = 1; k < run.samples.size(); ++k) {
    const double a = signal(run.samples[k - 1]), b = signal(run.samples[k]);
    if (a < 0.0 && b >= 0.0) {
      const double ta = run.samples[k - 1].sample.t, tb = run.samples[k].sample.t;
      crossings.push_back(ta + (tb - ta) * a / (a - b));
    }
  }
  if (crossings.size() < 2) return 0.0;
  return (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
}

TEST(Transient, BendingPeriodOfTipBodyMatchesClosedForm) {
  // Tip mass 1 kg with negligible rotary inertia (1e-8 kg m^2). The tip starts on the slow mode
  // of the 2 x 2 problem [12 -6l; -6l 4l^2] EI/l^3 x = w^2 diag(m, J) x, turning at theta/y of its
  // lateral velocity, so the fast rotary mode (2.6e5 rad/s) stays at rest.
  const double m = 1.0, j = 1e-8, ei = kE * kI;
  const double b = 4 * ei + 12 * ei * j, w2 = (b - std::sqrt(b * b - 48 * ei * ei * j)) / (2 * j);
  const double ratio = (12 * ei - w2 * m) / (6 * ei);
  char fields[256];
  std::snprintf(fields, sizeof fields,
                R"("mass": 1.0, "inertia": [1e-8, 1e-8, 1e-8], "velocity": [0, 1e-3, 0],
                   "angular_velocity": [0, 0, %.17g])",
                ratio * 1e-3);
  const Model model = testing::scene_from_json(cantilever(fields));
  const double exact = 2 * kPi * std::sqrt(m * std::pow(kL, 3) / (3 * ei));
  // BDF orders 3-5 are unstable near the imaginary axis: with the undamped rotary mode at
  // 2.6e5 rad/s they are held to steps of ~1e-6 s (2.9e6 steps here); A-stable BDF2 is not.
  TransientOptions o = testing::options(20 * exact, exact / 2000, 1e-10, 1e-14);
  o.integrator.max_order = 2;
  const TransientRun run = testing::simulate(model, o);
  ASSERT_TRUE(run.result.ok) << run.result.message;
  const double measured = period(run, [](const Snapshot& s) { return s.c[1](1); });
  std::printf(
      "bending period: measured %.12f s, closed form %.12f s, relative error %.2e (%ld steps)\n",
      measured, exact, measured / exact - 1, run.result.stats.steps);
  EXPECT_NEAR(measured / exact, 1.0, 1e-6);
}

TEST(Transient, AxialPeriodOfTipBodyMatchesClosedForm) {
  const Model model = testing::scene_from_json(
      cantilever(R"("mass": 2.0, "inertia": [1e-4, 1e-4, 1e-4], "velocity": [1e-3, 0, 0])"));
  const double exact = 2 * kPi * std::sqrt(2.0 * kL / (kE * kArea));
  const TransientRun run =
      testing::simulate(model, testing::options(20 * exact, exact / 2000, 1e-11, 1e-15));
  ASSERT_TRUE(run.result.ok) << run.result.message;
  const double measured = period(run, [](const Snapshot& s) { return s.c[1](0) - 1.0; });
  std::printf("axial period: measured %.12f s, closed form %.12f s, relative error %.2e\n",
              measured, exact, measured / exact - 1);
  EXPECT_NEAR(measured / exact, 1.0, 1e-6);
}

TEST(Transient, TorsionalPeriodOfTipBodyMatchesClosedForm) {
  const double jx = 2e-3;
  const Model model = testing::scene_from_json(cantilever(
      R"("mass": 1.0, "inertia": [2e-3, 1e-3, 1e-3], "angular_velocity": [1e-3, 0, 0])"));
  const double ix = model.beams[0].gj / kG;
  const double exact = 2 * kPi * std::sqrt(kL * jx / (kG * ix));
  const TransientRun run =
      testing::simulate(model, testing::options(20 * exact, exact / 2000, 1e-11, 1e-15));
  ASSERT_TRUE(run.result.ok) << run.result.message;
  // Twist angle about x: 2 q1 q0 ~ angle for small angles; the sign is what matters.
  const double measured = period(run, [](const Snapshot& s) { return s.q[1](1) * s.q[1](0); });
  std::printf("torsional period: measured %.12f s, closed form %.12f s, relative error %.2e\n",
              measured, exact, measured / exact - 1);
  EXPECT_NEAR(measured / exact, 1.0, 1e-6);
}

}  // namespace
}  // namespace beamrail

namespace beamrail {
namespace {

// theta / u of the slow bending mode of a tip body (mass m, rotary inertia j) on a cantilever:
// the smaller root of j w^4 - (4 + 12 j / (m l^2)) EI w^2 / l ... for l = 1, from the 2 x 2
// problem.
double slow_mode_ratio(double m, double j, double ei) {
  const double b = 4 * ei * m + 12 * ei * j;
  const double w2 = (b - std::sqrt(b * b - 48 * ei * ei * j * m)) / (2 * j * m);
  return (12 * ei - w2 * m) / (6 * ei);
}

// A tip body vibrating at small amplitude in both bending planes (slow modes) and in torsion.
std::string vibrating_tip() {
  const double ei = kE * kI, vy = 1e-3, vz = -8e-4;
  char fields[320];
  std::snprintf(fields, sizeof fields,
                R"("mass": 1.0, "inertia": [2e-3, 1e-3, 1.5e-3], "velocity": [0, %.17g, %.17g],
                   "angular_velocity": [0.02, %.17g, %.17g])",
                vy, vz, -slow_mode_ratio(1.0, 1e-3, ei) * vz,
                slow_mode_ratio(1.0, 1.5e-3, ei) * vy);
  return fields;
}

TEST(Transient, UndampedFreeVibrationKeepsTotalEnergy) {
  const Model model = testing::scene_from_json(cantilever(vibrating_tip()));
  const double slow = 2 * kPi * std::sqrt(1.0 * std::pow(kL, 3) / (3 * kE * kI));
  // BDF damps an oscillation by ~C (h w)^(q+1) per step whatever the tolerance, so over 500
  // torsion periods the step size, not rtol, sets the drift (1.0e-6 at rtol 1e-12 with free
  // steps; 8.6e-8 with steps <= 5e-5 s).
  TransientOptions o = testing::options(50 * slow, slow / 20, 1e-12, 1e-14);
  o.integrator.max_step = 5e-5;
  const TransientRun run = testing::simulate(model, o);
  ASSERT_TRUE(run.result.ok) << run.result.message;
  const double e0 = run.samples.front().sample.energy();
  double worst = 0;
  for (const Snapshot& s : run.samples)
    worst = std::max(worst, std::abs(s.sample.energy() / e0 - 1));
  std::printf(
      "undamped vibration (bending in y and z, torsion), 50 periods: max |E/E0 - 1| = %.2e "
      "(%ld steps)\n",
      worst, run.result.stats.steps);
  EXPECT_LT(worst, 1e-6);
}

TEST(Transient, DampingNeverIncreasesTotalEnergy) {
  const Model model = testing::scene_from_json(cantilever(vibrating_tip(), R"(, "damping": 2e-4)"));
  const TransientRun run = testing::simulate(model, testing::options(2.0, 1e-3, 1e-10, 1e-14));
  ASSERT_TRUE(run.result.ok) << run.result.message;
  const double e0 = run.samples.front().sample.energy();
  double largest_rise = -1;
  for (size_t k = 1; k < run.samples.size(); ++k)
    largest_rise = std::max(
        largest_rise, (run.samples[k].sample.energy() - run.samples[k - 1].sample.energy()) / e0);
  const double lost = 1 - run.samples.back().sample.energy() / e0;
  std::printf("damped vibration: largest rise between samples %.2e E0, lost %.4f of E0 in 2 s\n",
              largest_rise, lost);
  EXPECT_LE(largest_rise, 0.0);
  EXPECT_GT(lost, 0.1);  // the damping does act
}

// A 1 kg tip on a 1 m steel cantilever of 10 mm square section, pulled down by 1 N times the
// time function `time` (JSON).
Model loaded_tip(const std::string& time) {
  return testing::scene_from_json(R"({
      "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
      "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
      "bodies": [{"name": "tip", "mass": 1.0, "inertia": [1e-4, 1e-4, 1e-4], "position": [1, 0, 0]}],
      "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
                 "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq"}],
      "loads": [{"type": "force", "body": "tip", "value": [0, -1, 0], "time": )" +
                                  time + "}]}");
}

// A load's breakpoint within rounding of an output time: a table knot at 0.011 s with outputs
// every 1e-4 s (the 110th at 0.011000000000000001). Every method once failed there, asked for a
// step of 1.7e-18 s ("tout too close to t0", "the step size fell below the roundoff of the
// time"); now the two times are one, and each run agrees with the same load whose knot is the
// output time itself.
TEST(Transient, ABreakpointWithinRoundingOfAnOutputTimeIsThatTime) {
  const auto scene = [](double knot) {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", knot);
    return loaded_tip(R"({"type": "table", "t": [0.001, )" + std::string(text) +
                      R"(], "v": [0, 1]})");
  };
  const double on_output = 110 * 1e-4;
  ASSERT_NE(on_output, 0.011);
  const Model knot = scene(0.011), output = scene(on_output);
  for (const char* method : {"bdf", "dirk", "erk", "modal", "auto"}) {
    TransientOptions o = testing::options(0.012, 1e-4, 1e-8, 1e-11);
    o.integrator.method = *method_from_name(method);
    const TransientRun a = testing::simulate(knot, o), b = testing::simulate(output, o);
    ASSERT_TRUE(a.result.ok) << method << ": " << a.result.message;
    ASSERT_TRUE(b.result.ok) << method << ": " << b.result.message;
    EXPECT_EQ(a.result.t_reached, 0.012) << method;
    EXPECT_EQ(a.samples.size(), b.samples.size()) << method;
    const double difference = testing::run_error(knot, a, b);
    std::printf("%s: %zu samples, %.1e from the run whose knot is the output time\n", method,
                a.samples.size(), difference);
    EXPECT_LT(difference, 1e-8) << method;  // rtol
  }
}

// A step load after the start acts from its time on, in every method: the run stays at rest (to
// rounding) until the jump and then matches the same load stepped on at t = 0, shifted by the
// jump's time (`shift` output steps).
void expect_step_load_acts_from_its_time(const std::string& at, double output_step, int shift,
                                         double t_end) {
  const auto scene = [](const std::string& at) {
    return loaded_tip(R"({"type": "step", "at": )" + at + "}");
  };
  const Model late = scene(at), early = scene("0");
  struct Method {
    const char* name;
    double fixed_step;
  };
  for (const Method m : {Method{"bdf", 0}, Method{"dirk", 0}, Method{"erk", 0}, Method{"modal", 0},
                         Method{"auto", 0}, Method{"dirk", 5e-6}}) {
    TransientOptions o = testing::options(t_end, output_step, 1e-9, 1e-12);
    o.integrator.method = *method_from_name(m.name);
    o.integrator.fixed_step = m.fixed_step;
    const TransientRun a = testing::simulate(late, o);
    o.t_end = t_end - shift * output_step;
    const TransientRun b = testing::simulate(early, o);
    ASSERT_TRUE(a.result.ok && b.result.ok)
        << m.name << ": " << a.result.message << b.result.message;
    ASSERT_EQ(a.samples.size(), b.samples.size() + shift) << m.name;
    const int tip = testing::body_index(late, "tip");
    double before = 0.0, after = 0.0, motion = 0.0;
    for (int k = 0; k < static_cast<int>(a.samples.size()); ++k) {
      const Vec3 d = a.samples[k].c[tip] - a.samples[0].c[tip];
      if (k <= shift) {
        before = std::max(before, d.norm());
      } else {
        const Vec3 e = b.samples[k - shift].c[tip] - b.samples[0].c[tip];
        after = std::max(after, (d - e).norm());
        motion = std::max(motion, e.norm());
      }
    }
    std::printf(
        "step at %s s, %s%s: before the jump %.1e m, after it %.1e of the motion from the "
        "shifted run\n",
        at.c_str(), m.name, m.fixed_step > 0.0 ? " fixed_step" : "", before, after / motion);
    EXPECT_LT(before, 1e-14) << m.name;         // the rounding of 1 m coordinates
    EXPECT_LT(after / motion, 1e-7) << m.name;  // 100 rtol
  }
}

// A step's last stage (c = 1) at the jump once saw the load on: dirk and erk then moved 5e-6 m
// before the jump in their interpolated outputs, modal ended 2.7e-7 off (on a 3-segment chain at
// a fixed step of 0.1 ms, 8 % of the motion).
TEST(Transient, AStepLoadActsFromItsTimeOnInEveryMethod) {
  expect_step_load_acts_from_its_time("0.01005", 5e-5, 201, 0.02);
}

// A jump a rounding error after an output time (100 x 7e-5 = 0.006999999999999999 against a
// step at 0.007): the methods restart there, before the jump, and their first stage once saw the
// load off (auto ended 2.6 rtol off on a tip-body cantilever, a fixed-step DIRK 1.1e-3).
TEST(Transient, AStepLoadARoundingErrorAfterAnOutputTimeActsFromItsTime) {
  expect_step_load_acts_from_its_time("0.007", 7e-5, 100, 0.014);
}

}  // namespace
}  // namespace beamrail
