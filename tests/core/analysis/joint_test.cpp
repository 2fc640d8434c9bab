// Joints (docs/model.md "Joints"): spherical, revolute and fixed penalty elements between two
// bodies. Checked against what does not use the joint's tangent or stiffness: central differences
// of the forces, the large-angle pendulum's period by the complete elliptic integral (computed
// here by the arithmetic-geometric mean), Euler's load of a pinned-pinned column built with
// revolute joints, and one body in place of two fixed together.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "core/analysis/buckling_analysis.hpp"
#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/static_analysis.hpp"
#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"
#include "tests/support/scene_builder.hpp"
#include "tests/support/transient_run.hpp"

namespace beamrail {
namespace {

using testing::body_index;
using testing::joint;
using testing::Scene;
using testing::vec;
constexpr double kPi = std::numbers::pi;

Vec4 quaternion_of(const Mat3& a) {
  const Eigen::Quaterniond q(a);
  return Vec4(q.w(), q.x(), q.y(), q.z());
}

// --- The tangent against central differences of the forces --------------------------------------

// Two turned bodies joined by one joint of `type`, moved away from the joint's rest state; the
// stiffness matrix against central differences of the generalized forces (relative to the
// largest entry).
double joint_tangent_error(const std::string& type, bool rotation_only) {
  Scene s;
  s.body("a", 2.0, Vec3(0.3, 0.2, 0.25), Vec3(0.1, 0.2, -0.1));
  const Vec4 qa = quaternion_of(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).matrix());
  s.last_body()["orientation"] = {qa(0), qa(1), qa(2), qa(3)};
  s.body("b", 1.5, Vec3(0.2, 0.3, 0.1), Vec3(0.6, 0.1, 0.2));
  const Vec4 qb = quaternion_of(Eigen::AngleAxisd(-0.4, Vec3(2, -1, 1).normalized()).matrix());
  s.last_body()["orientation"] = {qb(0), qb(1), qb(2), qb(3)};
  s.j["joints"] = Json::array({joint("j", type, "a", "b", Vec3(0.35, 0.15, 0.05))});
  if (type == "revolute") s.j["joints"][0]["axis"] = vec(0.3, -0.5, 1.0);
  Model model = s.model();
  // Without the translational penalty: the rotational terms (smaller by k_m / k_f) alone.
  if (rotation_only) model.joints[0].k_force = 0.0;
  Data data(model);
  Eigen::VectorXd move(12);
  move << 0.01, -0.02, 0.015, 0.3, -0.2, 0.4, -0.01, 0.03, 0.02, -0.5, 0.25, 0.1;
  apply_increment(model, data, move);
  compute_wrenches(model, data, 0.0);
  compute_tangent(model, data, 0.0, false);
  const Eigen::MatrixXd k(stiffness_matrix(model, data));
  Eigen::MatrixXd fd(12, 12);
  const double h = 1e-6;
  for (int c = 0; c < 12; ++c) {
    const auto wrench_at = [&](double step) {
      Data moved = data;
      apply_increment(model, moved, step * Eigen::VectorXd::Unit(12, c));
      compute_wrenches(model, moved, 0.0);
      return wrench_vector(model, moved);
    };
    fd.col(c) = (wrench_at(h) - wrench_at(-h)) / (2.0 * h);
  }
  return (k - fd).cwiseAbs().maxCoeff() / fd.cwiseAbs().maxCoeff();
}

TEST(Joints, TangentEqualsCentralDifferencesOfTheForces) {
  for (const char* type : {"spherical", "revolute", "fixed"}) {
    for (bool rotation_only : {false, true}) {
      if (rotation_only && std::string(type) == "spherical") continue;
      const double error = joint_tangent_error(type, rotation_only);
      std::printf("%s joint%s: tangent against central differences %.2e (of the largest entry)\n",
                  type, rotation_only ? ", rotational terms alone" : "", error);
      // Central differences with h = 1e-6: truncation ~h^2, rounding ~1e-16 / h.
      EXPECT_LT(error, 1e-7) << type;
    }
  }
}

// --- (a) The large-angle pendulum ---------------------------------------------------------------

// K(k) = pi / (2 AGM(1, sqrt(1 - k^2))), the arithmetic-geometric mean iterated to convergence.
double elliptic_k(double k) {
  double a = 1.0, b = std::sqrt(1.0 - k * k);
  for (int i = 0; i < 40 && std::abs(a - b) > 1e-16 * a; ++i) {
    const double m = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = m;
  }
  return kPi / (2.0 * a);
}

// A rod-like body (m = 1 kg, centre d = 0.5 m from the pivot, I_c = m (2d)^2 / 12) on a revolute
// joint to ground about z, under gravity -y, released at rest at theta0 = 120 degrees.
struct PendulumRun {
  bool ok = false;
  std::string message;
  double period = 0.0;
  double max_stretch = 0.0;  // largest |distance pivot-centre| - d [m]
};

PendulumRun pendulum(double relative_compliance, double rtol, double theta0) {
  const double m = 1.0, d = 0.5, ic = m * 4 * d * d / 12;
  Scene s;
  s.j["gravity"] = vec(0, -9.81, 0);
  s.body("bob", m, Vec3(ic, ic, ic), Vec3(d * std::sin(theta0), -d * std::cos(theta0), 0));
  s.j["joints"] = Json::array({joint("pivot", "revolute", "ground", "bob", Vec3::Zero())});
  s.j["joints"][0]["axis"] = vec(0, 0, 1);
  s.j["joints"][0]["relative_compliance"] = relative_compliance;
  const Model model = s.model();
  const int b = body_index(model, "bob");
  TransientOptions options = testing::options(2.0, 2e-3, rtol, 1e-3 * rtol * d);
  options.integrator.method = IntegratorMethod::kBdf;
  const testing::TransientRun run = testing::simulate(model, options);
  PendulumRun out;
  out.ok = run.result.ok;
  out.message = run.result.message;
  // theta = atan2(x, -y) and its rate; the times it crosses 0 by cubic Hermite interpolation.
  std::vector<double> crossings;
  for (size_t k = 0; k + 1 < run.samples.size(); ++k) {
    const auto state = [&](size_t i, double* theta, double* rate) {
      const Vec3 c = run.samples[i].c[b], v = run.samples[i].pose[b].v;
      *theta = std::atan2(c(0), -c(1));
      *rate = (-c(1) * v(0) + c(0) * v(1)) / (c(0) * c(0) + c(1) * c(1));
    };
    out.max_stretch = std::max(out.max_stretch, std::abs(run.samples[k].c[b].norm() - d));
    double y0, r0, y1, r1;
    state(k, &y0, &r0);
    state(k + 1, &y1, &r1);
    if ((y0 > 0) == (y1 > 0)) continue;
    const double t0 = run.samples[k].sample.t, h = run.samples[k + 1].sample.t - t0;
    const auto hermite = [&](double s, double* slope) {
      const double h00 = 2 * s * s * s - 3 * s * s + 1, h10 = s * s * s - 2 * s * s + s;
      const double h01 = -2 * s * s * s + 3 * s * s, h11 = s * s * s - s * s;
      *slope = ((6 * s * s - 6 * s) * y0 + (3 * s * s - 4 * s + 1) * h * r0 +
                (-6 * s * s + 6 * s) * y1 + (3 * s * s - 2 * s) * h * r1) /
               h;
      return h00 * y0 + h10 * h * r0 + h01 * y1 + h11 * h * r1;
    };
    double s = y0 / (y0 - y1);
    for (int it = 0; it < 20; ++it) {
      double slope;
      const double y = hermite(s, &slope);
      s -= y / (slope * h);
    }
    crossings.push_back(t0 + s * h);
  }
  if (crossings.size() >= 2) out.period = 2.0 * (crossings[1] - crossings[0]);
  return out;
}

TEST(Joints, LargeAnglePendulumOnARevoluteJointHasTheEllipticIntegralPeriod) {
  const double m = 1.0, d = 0.5, g = 9.81, theta0 = 120.0 * kPi / 180.0;
  const double io = m * 4 * d * d / 12 + m * d * d;
  const double exact = 4.0 * std::sqrt(io / (m * g * d)) * elliptic_k(std::sin(theta0 / 2));
  std::printf("pendulum at 120 degrees: exact period %.12f s (K = %.12f)\n", exact,
              elliptic_k(std::sin(theta0 / 2)));
  const double rtol = 1e-10;
  for (double compliance : {1e-6, 1e-8, 1e-10}) {
    const PendulumRun run = pendulum(compliance, rtol, theta0);
    ASSERT_TRUE(run.ok) << run.message;
    ASSERT_GT(run.period, 0.0);
    const double error = std::abs(run.period - exact) / exact;
    std::printf(
        "  relative compliance %.0e, bdf rtol %.0e: period %.12f s, error %.2e, largest stretch "
        "%.2e d\n",
        compliance, rtol, run.period, error, run.max_stretch / d);
    // The joint's stretch lengthens the pendulum by about the stretch: the period error is the
    // compliance error (a few relative_compliance) or the integrator's, whichever is larger.
    EXPECT_LT(run.max_stretch / d, 10 * compliance);
    EXPECT_LT(error, std::max(10 * compliance, 100 * rtol));
  }
}

// The same pendulum hanging at rest: the modal analysis about its static equilibrium swings at
// omega^2 = m g d / I_O (the joint's tension turning with it); the joint's own modes lie far above.
TEST(Joints, HangingPendulumSwingsAtItsSmallAngleFrequency) {
  const double m = 1.0, d = 0.5, g = 9.81, ic = m * 4 * d * d / 12;
  Scene s;
  s.j["gravity"] = vec(0, -g, 0);
  s.body("bob", m, Vec3(ic, ic, ic), Vec3(0, -d, 0));
  s.j["joints"] = Json::array({joint("pivot", "revolute", "ground", "bob", Vec3::Zero())});
  s.j["joints"][0]["axis"] = vec(0, 0, 1);
  const Model model = s.model();
  Data data(model);
  const StaticResult equilibrium = solve_static(model, StaticOptions{}, data);
  ASSERT_TRUE(equilibrium.ok) << equilibrium.message;
  ModalOptions options;
  options.modes = 2;
  const ModalResult modal = solve_modal(model, options, data);
  ASSERT_GE(modal.modes.size(), 2u) << modal.message;
  const double exact = m * g * d / (ic + m * d * d);
  const double error = std::abs(modal.modes[0].eigenvalue - exact) / exact;
  std::printf("hanging pendulum: omega^2 = %.10f (exact %.10f, error %.2e); next mode %.3e\n",
              modal.modes[0].eigenvalue, exact, error, modal.modes[1].eigenvalue);
  EXPECT_LT(error, 10 * 1e-6);  // the default relative compliance
  EXPECT_GT(modal.modes[1].eigenvalue, 1e5 * exact);
}

// A joint's penalty stiffness does not depend on where the scene sits: the hanging pendulum
// above, moved 1e4 m from the origin, has the same joint stiffness (the ground's "centre", the
// origin, once gave its joint a lever of 1e4 m: 2e4 times softer, stretching 8 mm under the bob's
// weight), and so the same frequency to the closed form's accuracy.
TEST(Joints, AJointsStiffnessDoesNotDependOnWhereTheSceneSits) {
  const double m = 1.0, d = 0.5, g = 9.81, ic = m * 4 * d * d / 12;
  double omega2[2] = {0.0, 0.0}, k_force[2] = {0.0, 0.0}, k_moment[2] = {0.0, 0.0};
  for (int far = 0; far < 2; ++far) {
    const Vec3 at = far ? Vec3(1e4, 0, 0) : Vec3::Zero();
    Scene s;
    s.j["gravity"] = vec(0, -g, 0);
    s.body("bob", m, Vec3(ic, ic, ic), at + Vec3(0, -d, 0));
    s.j["joints"] = Json::array({joint("pivot", "revolute", "ground", "bob", at)});
    s.j["joints"][0]["axis"] = vec(0, 0, 1);
    const Model model = s.model();
    ASSERT_EQ(model.joints.size(), 1u);
    k_force[far] = model.joints[0].k_force;
    k_moment[far] = model.joints[0].k_moment;
    Data data(model);
    ASSERT_TRUE(solve_static(model, StaticOptions{}, data).ok);
    ModalOptions options;
    options.modes = 1;
    const ModalResult modal = solve_modal(model, options, data);
    ASSERT_GE(modal.modes.size(), 1u) << modal.message;
    omega2[far] = modal.modes[0].eigenvalue;
  }
  const double exact = m * g * d / (ic + m * d * d);
  std::printf(
      "joint stiffness at the origin %.6e N/m, 1e4 m away %.6e N/m; omega^2 %.10f and "
      "%.10f (exact %.10f)\n",
      k_force[0], k_force[1], omega2[0], omega2[1], exact);
  EXPECT_EQ(k_force[1], k_force[0]);
  EXPECT_EQ(k_moment[1], k_moment[0]);
  EXPECT_LT(std::abs(omega2[1] - exact) / exact, 10 * 1e-6);
  EXPECT_LT(std::abs(omega2[0] - exact) / exact, 10 * 1e-6);
}

// --- (b) A pinned-pinned Euler column built with revolute joints -------------------------------

// A steel column along x (L = 1 m, bending as a 10 mm square, 100 times its area: Euler's load
// is that of an inextensible column, and with the square's own area the shortening under it,
// P / EA = 8e-5, raises the discrete buckling load by 1.5e-4, measured), in n segments between end
// bodies "bottom" and "top"; revolute joints about z pin the bottom to ground and the top to a
// slider that a prismatic rail along x holds sideways (the rail has no axial stiffness: the
// compression reaches the column). Compressed by p times Euler's load pi^2 EI / L^2 at the slider.
constexpr double kE = 2.1e11, kG = 8.0e10, kDensity = 7850.0, kSide = 0.01;

Model pinned_column(int n, double p) {
  const double ei = kE * kSide * kSide * kSide * kSide / 12;
  Scene s;
  s.material("steel", kE, kG, kDensity);
  const double i = kSide * kSide * kSide * kSide / 12;
  s.custom("bar", 100 * kSide * kSide, 0.141 * kSide * kSide * kSide * kSide, i, i);
  s.j["bodies"].push_back({{"name", "bottom"}, {"position", vec(0, 0, 0)}});
  s.j["bodies"].push_back({{"name", "top"}, {"position", vec(1, 0, 0)}});
  s.body("slider", 0.1, Vec3(1e-4, 1e-4, 1e-4), Vec3(1, 0, 0));
  s.beam("column", "bottom", "top", Vec3::Zero(), Vec3(1, 0, 0), "steel", "bar");
  s.last_beam()["segments"] = n;
  s.rail("guide", "prismatic", "ground", "slider", Vec3(1.1, 0, 0), Vec3(1, 0, 0), "steel", "bar");
  s.j["joints"] = Json::array({joint("pin_bottom", "revolute", "ground", "bottom", Vec3::Zero()),
                               joint("pin_top", "revolute", "top", "slider", Vec3(1, 0, 0))});
  s.j["joints"][0]["axis"] = vec(0, 0, 1);
  s.j["joints"][1]["axis"] = vec(0, 0, 1);
  s.force("slider", Vec3(-p * kPi * kPi * ei, 0, 0));
  return s.model();
}

TEST(Joints, PinnedPinnedColumnWithRevoluteJointsBucklesAtEulersLoad) {
  std::vector<double> factors;
  for (int n : {4, 8, 16, 32}) {
    const Model model = pinned_column(n, 1.0);
    const Model reference = with_loads(
        model, [](const Load&) { return false; }, false);
    Data data(reference);
    const BucklingResult result = solve_buckling(reference, model, BucklingOptions{}, data);
    ASSERT_TRUE(result.ok) << result.message;
    factors.push_back(buckling_factor(result, 1));
    std::printf("pinned-pinned column, %2d segments: P / (pi^2 EI / L^2) = %.8f (%+.2e)\n", n,
                factors.back(), factors.back() - 1.0);
  }
  const size_t last = factors.size() - 1;
  const double order =
      std::log2((factors[last - 2] - factors[last - 1]) / (factors[last - 1] - factors[last]));
  // Richardson twice (the errors in h^2 and h^4 of the cubic segments) from 8, 16 and 32.
  const double r16 = (4 * factors[last - 1] - factors[last - 2]) / 3;
  const double r32 = (4 * factors[last] - factors[last - 1]) / 3;
  const double extrapolated = (16 * r32 - r16) / 15;
  std::printf("  observed order %.3f, extrapolated (h^2) %.8f, (h^2, h^4) %.8f\n", order, r32,
              extrapolated);
  for (size_t k = 1; k < factors.size(); ++k)
    EXPECT_LT(std::abs(factors[k] - 1), std::abs(factors[k - 1] - 1));
  EXPECT_NEAR(order, 2.0, 0.1);
  EXPECT_NEAR(extrapolated, 1.0, 1e-5);
}

// --- (c) Two bodies fixed together deflect as one -----------------------------------------------

// A cantilever of two beams (ground - a, b - tip) whose bodies a and b are held by a fixed joint,
// against the same cantilever with a and b one body; tip loaded by a force and a torque.
Vec3 tip_deflection(bool jointed, double compliance, double* max_deflection) {
  Scene s;
  s.material("steel", kE, kG, kDensity);
  s.square("bar", kSide);
  s.body("a", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(1, 0, 0));
  if (jointed) s.body("b", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(1.05, 0, 0));
  s.body("tip", 0.5, Vec3(1e-3, 1e-3, 1e-3), Vec3(2.1, 0, 0));
  s.beam("first", "ground", "a", Vec3::Zero(), Vec3(1, 0, 0), "steel", "bar");
  s.beam("second", jointed ? "b" : "a", "tip", Vec3(1.1, 0, 0), Vec3(2.1, 0, 0), "steel", "bar");
  if (jointed) {
    s.j["joints"] = Json::array({joint("weld", "fixed", "a", "b", Vec3(1.05, 0, 0))});
    s.j["joints"][0]["relative_compliance"] = compliance;
  }
  s.force("tip", Vec3(30, -40, 25));
  s.torque("tip", Vec3(5, 3, -4));
  const Model model = s.model();
  Data data(model);
  const StaticResult r = solve_static(model, StaticOptions{}, data);
  EXPECT_TRUE(r.ok) << r.message;
  const int tip = body_index(model, "tip");
  *max_deflection = data.pose[tip].u.norm();
  return data.pose[tip].u;
}

TEST(Joints, TwoBodiesHeldByAFixedJointDeflectAsOne) {
  double scale = 0.0;
  const Vec3 one = tip_deflection(false, 0.0, &scale);
  std::vector<double> differences;
  for (double compliance : {1e-4, 1e-6}) {
    double ignored;
    const Vec3 two = tip_deflection(true, compliance, &ignored);
    const double difference = (two - one).norm() / scale;
    std::printf(
        "fixed joint, relative compliance %.0e: tip deflection %.4e m, differs from one body by "
        "%.2e of it\n",
        compliance, scale, difference);
    // The documented bound: the joint adds at most relative_compliance of the deflection.
    EXPECT_LT(difference, compliance);
    EXPECT_GT(difference, 1e-3 * compliance);  // the joint is not rigid: the penalty is measured
    differences.push_back(difference);
  }
  // The difference is the joint's compliance: it falls in proportion to it.
  EXPECT_NEAR(differences[0] / differences[1], 100.0, 5.0);
}

}  // namespace
}  // namespace beamrail
