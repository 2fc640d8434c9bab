// Bodies moved as prescribed (core/model/motion.hpp): the time functions' integrals that give
// their poses, a base shaken along a beam's axis and a hub spun up through several turns, each
// against its closed form; the methods that refuse or choose for a scene with a drive.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "core/model/rotation.hpp"
#include "tests/support/scene_builder.hpp"
#include "tests/support/transient_run.hpp"

namespace beamrail {
namespace {

using testing::options;
using testing::Scene;
using testing::simulate;
using testing::TransientRun;
using testing::vec;
constexpr double kPi = std::numbers::pi;

// Composite three-point Gauss-Legendre rule of f over [a, b] in n intervals (exact for
// polynomials of degree 5; no evaluation at the ends, where a step jumps).
template <class F>
double gauss(const F& f, double a, double b, int n) {
  const double h = (b - a) / n, x = std::sqrt(0.6);
  double sum = 0.0;
  for (int k = 0; k < n; ++k) {
    const double m = a + (k + 0.5) * h;
    sum += 5.0 * f(m - 0.5 * h * x) + 8.0 * f(m) + 5.0 * f(m + 0.5 * h * x);
  }
  return sum * h / 18.0;
}

// Each time function's closed-form integral from 0 against Gauss-Legendre quadrature between its
// breakpoints (exact for the pieces that are polynomials, to rounding for the rest).
TEST(PrescribedMotion, TimeFunctionIntegralsMatchQuadrature) {
  std::vector<std::pair<std::string, TimeFunction>> functions;
  TimeFunction f;
  functions.push_back({"constant", f});
  f.type = TimeFunction::Type::kStep, f.at = 0.3;
  functions.push_back({"step", f});
  f.type = TimeFunction::Type::kRamp, f.from = 0.2, f.to = 0.7;
  functions.push_back({"ramp", f});
  f.type = TimeFunction::Type::kSmoothRamp;
  functions.push_back({"smooth ramp", f});
  f.type = TimeFunction::Type::kRamp, f.from = -0.4, f.to = 0.5;  // begun before t = 0
  functions.push_back({"ramp begun before 0", f});
  f.type = TimeFunction::Type::kHarmonic, f.frequency = 3.0, f.phase = 0.4;
  functions.push_back({"harmonic", f});
  f.type = TimeFunction::Type::kTable, f.t = {-0.1, 0.25, 0.5, 0.9}, f.v = {2.0, -1.0, 0.5, 3.0};
  functions.push_back({"table", f});
  for (const auto& [name, g] : functions) {
    std::vector<double> cuts{0.0};
    g.append_breakpoints(cuts);
    if (g.type == TimeFunction::Type::kSmoothRamp) cuts.insert(cuts.end(), {g.from, g.to});
    double worst = 0.0;
    for (double t : {0.05, 0.3, 0.45, 0.7, 1.3}) {
      std::vector<double> edges{0.0};
      for (double c : cuts)
        if (c > 0.0 && c < t) edges.push_back(c);
      std::sort(edges.begin(), edges.end());
      edges.push_back(t);
      double quadrature = 0.0;
      for (size_t k = 1; k < edges.size(); ++k) quadrature += gauss(g, edges[k - 1], edges[k], 400);
      worst = std::max(worst, std::abs(g.integral(t) - quadrature));
    }
    std::printf("%-20s worst |integral - quadrature| %.1e\n", name.c_str(), worst);
    EXPECT_LT(worst, 1e-13) << name;
  }
  // The smooth ramp rises from 0 to 1 with zero slope at both ends (central differences).
  const TimeFunction& smooth = functions[3].second;
  const double h = 1e-5;
  for (double end : {smooth.from, smooth.to}) {
    const double slope = (smooth(end + h) - smooth(end - h)) / (2 * h);
    EXPECT_LT(std::abs(slope), 1e-8) << end;
  }
  EXPECT_DOUBLE_EQ(smooth(0.45), 0.5);  // symmetric about its middle
  EXPECT_NEAR((smooth(0.45 + h) - smooth(0.45 - h)) / (2 * h), 2.0 / 0.5, 1e-8);
}

// A driven body's pose: a hub turned at first 90 degrees about z, spun about a tilted axis and
// moved along a ramped velocity. Its orientation is exp([n theta(t)]x) A0, its centre
// c0 + v F(t), with theta and F the integrals of the time functions.
TEST(PrescribedMotion, DrivenPoseIsTheIntegralOfItsVelocities) {
  Scene s;
  s.material("steel", 2.1e11, 8.0769e10).square("sq", 0.01);
  s.body("hub", 1.0, Vec3(1, 1, 1), Vec3(0.1, 0.2, 0.3));
  const double half = std::sqrt(0.5);
  s.last_body()["orientation"] = {half, 0.0, 0.0, half};
  s.last_body().erase("mass");
  s.last_body().erase("inertia");
  s.last_body()["motion"] = {
      {"velocity", vec(0.5, -1.0, 2.0)},
      {"velocity_time", {{"type", "ramp"}, {"from", 0.0}, {"to", 2.0}}},
      {"angular_velocity", vec(1.0, 2.0, 3.0)},
      {"angular_velocity_time", {{"type", "harmonic"}, {"frequency", 0.25}, {"phase", 0.3}}}};
  s.body("tip", 1.0, Vec3(1e-4, 1e-4, 1e-4), Vec3(1.1, 0.2, 0.3));
  s.beam("arm", "hub", "tip", Vec3(0.1, 0.2, 0.3), Vec3(1.1, 0.2, 0.3), "steel", "sq");
  const Model model = s.model();
  ASSERT_EQ(model.driven_bodies.size(), 1u);
  const int hub = model.driven_bodies[0];
  EXPECT_TRUE(model.bodies[hub].fixed);
  EXPECT_EQ(model.n_free(), 1);
  Data data(model);
  const Mat3 a0 = rotation_matrix<double>(Vec4(half, 0, 0, half));
  const Vec3 axis = Vec3(1, 2, 3).normalized(), v(0.5, -1.0, 2.0);
  for (double t : {0.0, 0.7, 1.9, 3.5}) {
    set_driven_poses(model, data, t);
    const double ramp = t < 2.0 ? t * t / 4.0 : 1.0 + (t - 2.0);  // integral of the ramp
    const double w = 2 * kPi * 0.25;
    const double angle = std::sqrt(14.0) * (std::cos(0.3) - std::cos(w * t + 0.3)) / w;
    const Mat3 expected = rotation_matrix<double>(quat_from_rotation_vector(angle * axis)) * a0;
    EXPECT_LT((data.pose[hub].A - expected).norm(), 1e-14) << t;
    EXPECT_LT((data.pose[hub].u - ramp * v).norm(), 1e-14) << t;
    EXPECT_LT((data.pose[hub].v - std::min(t / 2.0, 1.0) * v).norm(), 1e-14) << t;
    EXPECT_LT((data.pose[hub].omega - std::sqrt(14.0) * std::sin(w * t + 0.3) * axis).norm(), 1e-13)
        << t;
    EXPECT_LT((data.pose[hub].A * data.w[hub] - data.pose[hub].omega).norm(), 1e-13) << t;
  }
}

// A base shaken along the axis of a massless steel rod (10 mm square, 1 m, k = EA / L) carrying
// a 1 kg mass: x_b = X sin(W t) from rest. The mass follows
//   x(t) = X w^2 / (w^2 - W^2) (sin W t - (W / w) sin w t),  w^2 = k / m.
// The base's velocity X W cos(W t) is a harmonic velocity_time of phase pi / 2.
TEST(PrescribedMotion, ShakenBaseMovesTheMassAsTheClosedForm) {
  const double e = 2.1e11, area = 1e-4, m = 1.0, big_x = 1e-3;
  const double w = std::sqrt(e * area / m), big_w = 0.6 * w;
  Scene s;
  s.material("steel", e, 8.0769e10).square("sq", 0.01);
  s.j["bodies"].push_back(
      {{"name", "base"},
       {"position", vec(0, 0, 0)},
       {"motion",
        {{"velocity", vec(big_x * big_w, 0, 0)},
         {"velocity_time",
          {{"type", "harmonic"}, {"frequency", big_w / (2 * kPi)}, {"phase", kPi / 2}}}}}});
  s.body("mass", m, Vec3(1e-4, 1e-4, 1e-4), Vec3(1, 0, 0));
  s.beam("rod", "base", "mass", Vec3::Zero(), Vec3(1, 0, 0), "steel", "sq");
  const Model model = s.model();
  const int mass = testing::body_index(model, "mass");
  const double amplitude = big_x * w * w / (w * w - big_w * big_w);
  // The worst distance from the closed form over the run.
  const auto error_of = [&](const TransientRun& run) {
    double worst = 0.0;
    for (const auto& sample : run.samples) {
      const double t = sample.sample.t;
      const double exact = amplitude * (std::sin(big_w * t) - big_w / w * std::sin(w * t));
      worst = std::max(worst, std::abs(sample.c[mass].x() - 1.0 - exact));
      EXPECT_LT(std::abs(sample.c[mass].y()) + std::abs(sample.c[mass].z()), 1e-15);
    }
    return worst;
  };
  // The model is exact (a linear spring): what is left is the integrator's error, which falls
  // with its tolerance.
  std::vector<double> errors;
  std::vector<long> steps;
  for (const char* method : {"bdf", "auto"})
    for (double rtol : {1e-10, 1e-12}) {
      if (std::string(method) == "auto" && rtol < 1e-10) continue;
      TransientOptions o = options(0.02, 2e-4, rtol, 1e-14);
      o.integrator.method = *method_from_name(method);
      const TransientRun run = simulate(model, o);
      ASSERT_TRUE(run.result.ok) << method << ": " << run.result.message;
      errors.push_back(error_of(run));
      steps.push_back(run.result.stats.steps);
      std::printf("%s, rtol %.0e: %ld steps, worst error %.2e m of an amplitude %.2e m\n", method,
                  rtol, run.result.stats.steps, errors.back(), amplitude);
      if (std::string(method) == "auto") {
        ASSERT_FALSE(run.result.phases.empty());
        EXPECT_EQ(run.result.phases[0].method, "dirk");
        EXPECT_NE(run.result.phases[0].reason.find("body \"base\" moves as prescribed"),
                  std::string::npos)
            << run.result.phases[0].reason;
      }
    }
  EXPECT_LT(errors[1], 1e-7 * amplitude);
  EXPECT_GT(errors[0] / errors[1], 10.0);
  // auto: about as accurate as bdf at the same tolerance, in a quarter of the steps (an A-stable
  // DIRK). Both hold the mass's displacement to rtol of itself since the states hold
  // displacements (docs/model.md "Bodies"; before, to rtol of its 1 m distance from the origin):
  // at rtol 1e-10 dirk 3.2e-10 m (5.1e-10 before) in 948 steps, bdf 1.8e-10 m (9.8e-10 before)
  // in 3,964; from rtol 1e-8 to 1e-12 dirk's errors are 1.3 to 0.53 times bdf's, each falling
  // with rtol.
  EXPECT_LT(errors[2], 2.0 * errors[0]);
  EXPECT_LT(3 * steps[2], steps[0]);
  TransientOptions o = options(0.02, 2e-4, 1e-6, 1e-10);
  o.integrator.method = IntegratorMethod::kModal;
  const TransientRun modal = simulate(model, o);
  EXPECT_FALSE(modal.result.ok);
  EXPECT_NE(modal.result.message.find("moves as prescribed"), std::string::npos)
      << modal.result.message;
}

// A hub spun up about x by the smooth angular velocity profile w_s f(t) (f the smooth ramp from 0
// to T, the spin-up of Simo and Vu-Quoc's flexible beam), then held at w_s: 15 rad (2.4 turns) in
// 2 s. A shaft (torsion k = G Ix / L) carries a disc of polar inertia J; its twist psi = phi -
// theta obeys psi'' + w^2 psi = -theta'' = -(w_s / T)(1 - cos(nu t)), nu = 2 pi / T, w^2 = k / J:
//   t <= T: psi = -(w_s / T)(1 / w^2 - cos(nu t) / (w^2 - nu^2)) + C cos(w t),
//           C = (w_s / T)(1 / w^2 - 1 / (w^2 - nu^2));
//   t > T:  free vibration from psi(T), psi'(T).
// The twist is measured as the rotation vector of the disc relative to the hub.
TEST(PrescribedMotion, SpunUpHubTwistsTheShaftAsTheClosedForm) {
  const double ws = 10.0, big_t = 1.0, j = 0.02, w = 30.0, nu = 2 * kPi / big_t;
  const double g = 8.0769e10, ix = w * w * j / g;  // L = 1 m: k = G Ix
  Scene s;
  s.material("steel", 2.1e11, g).custom("shaft", 1e-4, ix, 1e-8, 1e-8);
  s.j["bodies"].push_back(
      {{"name", "hub"},
       {"position", vec(0, 0, 0)},
       {"motion",
        {{"angular_velocity", vec(ws, 0, 0)},
         {"angular_velocity_time", {{"type", "smooth_ramp"}, {"from", 0.0}, {"to", big_t}}}}}});
  s.body("disc", 1.0, Vec3(j, j, j), Vec3(1, 0, 0));
  s.beam("shaft", "hub", "disc", Vec3::Zero(), Vec3(1, 0, 0), "steel", "shaft");
  const Model model = s.model();
  const int hub = testing::body_index(model, "hub"), disc = testing::body_index(model, "disc");
  const double a = ws / big_t, c = a * (1 / (w * w) - 1 / (w * w - nu * nu));
  const auto during = [&](double t) {
    return -a * (1 / (w * w) - std::cos(nu * t) / (w * w - nu * nu)) + c * std::cos(w * t);
  };
  const auto during_rate = [&](double t) {
    return -a * nu * std::sin(nu * t) / (w * w - nu * nu) - c * w * std::sin(w * t);
  };
  const auto twist = [&](double t) {
    if (t <= big_t) return during(t);
    return during(big_t) * std::cos(w * (t - big_t)) +
           during_rate(big_t) / w * std::sin(w * (t - big_t));
  };
  TransientOptions o = options(2.0, 0.01, 1e-10, 1e-14);
  const TransientRun run = simulate(model, o);
  ASSERT_TRUE(run.result.ok) << run.result.message;
  double worst = 0.0, largest = 0.0, hub_error = 0.0;
  for (const auto& sample : run.samples) {
    const double t = sample.sample.t;
    const Mat3& a_hub = sample.pose[hub].A;
    const Vec3 relative = rotation_vector(sample.pose[disc].A * a_hub.transpose());
    worst = std::max(worst, std::abs(relative.x() - twist(t)));
    largest = std::max(largest, std::abs(twist(t)));
    // The hub's own angle: w_s times the smooth ramp's integral.
    TimeFunction f;
    f.type = TimeFunction::Type::kSmoothRamp, f.from = 0.0, f.to = big_t;
    const Mat3 turned =
        rotation_matrix<double>(quat_from_rotation_vector(Vec3(ws * f.integral(t), 0, 0)));
    hub_error = std::max(hub_error, (a_hub - turned).norm());
  }
  std::printf(
      "spin-up to %.0f rad/s, %.2f rad in %.0f s: %ld steps, twist amplitude %.3e rad, worst "
      "error %.2e rad; the hub's orientation within %.1e\n",
      ws, ws * (2.0 - big_t / 2), 2.0, run.result.stats.steps, largest, worst, hub_error);
  EXPECT_LT(hub_error, 1e-13);
  EXPECT_LT(worst, 1e-6 * largest);
}

}  // namespace
}  // namespace beamrail
