// Follower loads ("follows": true, docs/model.md "Loads"): a force or torque fixed in the body's
// frame. Checked against what does not use the code's tangent: central differences of the
// generalized forces, a free body's motion in closed form (with the velocity by an independent
// quadrature), Beck's column (flutter at 20.05 EI/L^2, where a dead load buckles it at
// pi^2/4 EI/L^2), a cantilever bent into a circle by an end moment, and the elastica under a tip
// force that stays perpendicular to the tip (by shooting on its differential equation).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "core/analysis/buckling_analysis.hpp"
#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/sensitivity.hpp"
#include "core/analysis/static_analysis.hpp"
#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"
#include "core/model/rotation.hpp"
#include "tests/support/scene_builder.hpp"
#include "tests/support/transient_run.hpp"

namespace beamrail {
namespace {

using testing::body_index;
using testing::Scene;
using testing::vec;
constexpr double kPi = std::numbers::pi;

Mat3 rotation_about(const Vec3& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

Vec4 quaternion_of(const Mat3& a) {
  const Eigen::Quaterniond q(a);
  return Vec4(q.w(), q.x(), q.y(), q.z());
}

// --- The scene reader -------------------------------------------------------------------------

// The value is given in global axes of the initial configuration and kept in body axes.
TEST(FollowerLoads, TheReaderKeepsTheValueInBodyAxes) {
  const Mat3 a0 = rotation_about(Vec3(1, 2, 3), 0.7);
  Scene s;
  s.body("b", 1.0, Vec3(1, 2, 2.5), Vec3(0.3, 0, 0));
  const Vec4 q = quaternion_of(a0);
  s.last_body()["orientation"] = {q(0), q(1), q(2), q(3)};
  s.force("b", Vec3(1, -2, 3));
  s.j["loads"].back()["follows"] = true;
  s.j["loads"].back()["point"] = vec(0.3, 0.5, 0);
  s.torque("b", Vec3(4, 5, -6));
  s.j["loads"].back()["follows"] = true;
  s.force("b", Vec3(7, 8, 9));
  s.j["loads"].back()["follows"] = false;
  const Model model = s.model();
  ASSERT_EQ(model.loads.size(), 3u);
  EXPECT_TRUE(model.loads[0].follows);
  EXPECT_LT((a0 * model.loads[0].value - Vec3(1, -2, 3)).norm(), 1e-14);
  EXPECT_LT((a0 * model.loads[0].offset - Vec3(0, 0.5, 0)).norm(), 1e-14);
  EXPECT_TRUE(model.loads[1].follows);
  EXPECT_LT((a0 * model.loads[1].value - Vec3(4, 5, -6)).norm(), 1e-14);
  EXPECT_FALSE(model.loads[2].follows);
  EXPECT_EQ(model.loads[2].value, Vec3(7, 8, 9));
  EXPECT_FALSE(is_conservative(model.loads[0]));
  EXPECT_FALSE(is_conservative(model.loads[1]));
  EXPECT_TRUE(is_conservative(model.loads[2]));
}

// --- (a) The load stiffness against central differences of the generalized forces ---------------

// A body turned away from its (rotated) initial orientation, loaded by one load; the tangent's
// load part d wrench / d (dc, dtheta) against central differences of the wrenches, column by
// column (relative to the largest entry).
double load_tangent_error(const Json& load, double* asymmetry) {
  Scene s;
  s.body("b", 2.0, Vec3(1, 2, 2.5), Vec3(0.3, -0.2, 0.1));
  const Vec4 q0 = quaternion_of(rotation_about(Vec3(1, -1, 2), 1.1));
  s.last_body()["orientation"] = {q0(0), q0(1), q0(2), q0(3)};
  s.j["loads"].push_back(load);
  const Model model = s.model();
  Data data(model);
  Eigen::VectorXd turn(6);
  turn << 0.01, -0.02, 0.03, 0.4, -0.3, 0.5;
  apply_increment(model, data, turn);
  const double t = 0.7;
  compute_wrenches(model, data, t);
  compute_tangent(model, data, t, false);
  const Eigen::MatrixXd k(stiffness_matrix(model, data));
  Eigen::MatrixXd fd(6, 6);
  const double h = 1e-5;
  for (int c = 0; c < 6; ++c) {
    const auto wrench_at = [&](double step) {
      Data moved = data;
      apply_increment(model, moved, step * Eigen::VectorXd::Unit(6, c));
      compute_wrenches(model, moved, t);
      return wrench_vector(model, moved);
    };
    fd.col(c) = (wrench_at(h) - wrench_at(-h)) / (2.0 * h);
  }
  *asymmetry = (k - k.transpose()).norm() / k.norm();
  return (k - fd).cwiseAbs().maxCoeff() / fd.cwiseAbs().maxCoeff();
}

TEST(FollowerLoads, LoadStiffnessEqualsCentralDifferencesOfTheForces) {
  const Json ramp = {{"type", "ramp"}, {"from", 0.0}, {"to", 1.0}};
  const struct {
    const char* what;
    Json load;
    bool follows;
  } cases[] = {
      {"follower force at an offset",
       {{"type", "force"},
        {"body", "b"},
        {"value", vec(30, -40, 25)},
        {"point", vec(0.8, 0.3, -0.4)},
        {"follows", true},
        {"time", ramp}},
       true},
      {"follower torque",
       {{"type", "torque"}, {"body", "b"}, {"value", vec(-5, 12, 7)}, {"follows", true}},
       true},
      {"dead force at an offset",
       {{"type", "force"},
        {"body", "b"},
        {"value", vec(30, -40, 25)},
        {"point", vec(0.8, 0.3, -0.4)}},
       false},
  };
  for (const auto& c : cases) {
    double asymmetry = 0.0;
    const double error = load_tangent_error(c.load, &asymmetry);
    std::printf("load stiffness, %s: relative error %.2e, asymmetry %.2f\n", c.what, error,
                asymmetry);
    EXPECT_LT(error, 1e-6) << c.what;
    // The follower's load stiffness alone is far from symmetric.
    if (c.follows) {
      EXPECT_GT(asymmetry, 0.1) << c.what;
    }
  }
}

// --- (b) A free body under a follower torque and a follower force ------------------------------

// The body spins up about its principal axis e (body z) from rest: omega = tau t / J,
// theta = tau t^2 / (2 J); the follower force along body x turns with it, so the centre's
// velocity is v(t) = (F / m) A0 integral_0^t Rz(theta(s)) e_x ds (Fresnel integrals), here by
// composite Gauss-Legendre quadrature (20 nodes on each of 400 panels; the integrand's phase
// changes by at most 0.03 rad per panel).
Vec3 fresnel_velocity(double t, double alpha) {
  static const double x[10] = {0.0765265211334973, 0.2277858511416451, 0.3737060887154195,
                               0.5108670019508271, 0.6360536807265150, 0.7463319064601508,
                               0.8391169718222188, 0.9122344282513259, 0.9639719272779138,
                               0.9931285991850949};
  static const double w[10] = {0.1527533871307258, 0.1491729864726037, 0.1420961093183820,
                               0.1316886384491766, 0.1181945319615184, 0.1019301198172404,
                               0.0832767415767048, 0.0626720483341091, 0.0406014298003869,
                               0.0176140071391521};
  const int panels = 400;
  const double h = t / panels;
  double cx = 0.0, sy = 0.0;
  for (int p = 0; p < panels; ++p) {
    const double mid = (p + 0.5) * h;
    for (int k = 0; k < 10; ++k)
      for (double sign : {-1.0, 1.0}) {
        const double s = mid + sign * 0.5 * h * x[k];
        const double theta = 0.5 * alpha * s * s;
        cx += 0.5 * h * w[k] * std::cos(theta);
        sy += 0.5 * h * w[k] * std::sin(theta);
      }
  }
  return Vec3(cx, sy, 0.0);
}

TEST(FollowerLoads, FreeBodySpunUpByAFollowerTorqueAndPushedByAFollowerForce) {
  const double mass = 2.0, tau = 0.3, force = 0.5;
  const Vec3 inertia(0.2, 0.25, 0.15);  // principal, body axes; the torque about body z
  const double alpha = tau / inertia(2);
  const Mat3 a0 = rotation_about(Vec3(1, 1, 0.5), 0.6);
  Scene s;
  s.body("b", mass, inertia, Vec3(0.2, -0.1, 0.4));
  const Vec4 q0 = quaternion_of(a0);
  s.last_body()["orientation"] = {q0(0), q0(1), q0(2), q0(3)};
  const Vec3 torque = a0 * Vec3(0, 0, tau), push = a0 * Vec3(force, 0, 0);  // given in global axes
  s.torque("b", torque).force("b", push);
  s.j["loads"][0]["follows"] = true;
  s.j["loads"][1]["follows"] = true;
  const Model model = s.model();
  const int b = body_index(model, "b");
  const double t_end = 3.0;  // theta reaches 3 rad x 3 / 2 ... 4.5 rad
  for (const auto& [method, rtol] :
       {std::pair{IntegratorMethod::kBdf, 1e-9}, std::pair{IntegratorMethod::kErk, 1e-9}}) {
    TransientOptions options = testing::options(t_end, 0.05, rtol, 1e-3 * rtol);
    options.integrator.method = method;
    const testing::TransientRun run = testing::simulate(model, options);
    ASSERT_TRUE(run.result.ok) << run.result.message;
    double angle_error = 0.0, omega_error = 0.0, velocity_error = 0.0;
    for (const testing::Snapshot& snap : run.samples) {
      const double t = snap.sample.t;
      const double theta = 0.5 * alpha * t * t;
      const Mat3 expected = a0 * rotation_about(Vec3::UnitZ(), theta);
      angle_error = std::max(angle_error, (snap.pose[b].A - expected).norm());
      omega_error =
          std::max(omega_error, (snap.w[b] - Vec3(0, 0, alpha * t)).norm() / (alpha * t_end));
      const Vec3 v = force / mass * (a0 * fresnel_velocity(t, alpha));
      velocity_error = std::max(velocity_error, (snap.pose[b].v - v).norm() / (force / mass));
    }
    std::printf(
        "free body, %s at rtol %.0e: rotation error %.2e, omega %.2e, velocity %.2e "
        "(relative)\n",
        method == IntegratorMethod::kBdf ? "bdf" : "erk", rtol, angle_error, omega_error,
        velocity_error);
    // Within the tolerance: a global error of a few tens of rtol at most (measured: 14 rtol for
    // bdf, 1.2 for erk; a force or torque of the wrong direction would be off by O(1)).
    EXPECT_LT(angle_error, 30 * rtol);
    EXPECT_LT(omega_error, 30 * rtol);
    EXPECT_LT(velocity_error, 30 * rtol);
  }
}

// --- (c) Beck's column --------------------------------------------------------------------------

// A uniform steel cantilever along x (L = 1 m), in n segments with their mass (rho S = 0.785
// kg/m), ending at a tip body without mass of its own; r = sqrt(Iy / S) = 1 mm, so rotary
// inertia and the shortening under load (strain 2e-5 at the flutter load) are small. It bends
// most easily along z (E Iy); Iz = 100 Iy keeps the other plane's modes above the first two.
constexpr double kE = 2.1e11, kG = 8.0e10, kDensity = 7850.0, kArea = 1e-4, kIy = 1e-10;
constexpr double kEIy = kE * kIy;  // [N m^2], with L = 1 m also the unit EI / L^2 of the loads

// The column compressed at its tip by p EI/L^2, a follower force (tangent to the tip) or one of
// fixed direction.
Scene beck_scene(int n, double p, bool follows) {
  Scene s;
  s.material("steel", kE, kG, kDensity);
  s.custom("strip", kArea, 1e-8, kIy, 100 * kIy);
  s.j["bodies"].push_back({{"name", "tip"}, {"position", vec(1, 0, 0)}});
  s.beam("column", "ground", "tip", Vec3::Zero(), Vec3(1, 0, 0), "steel", "strip");
  s.last_beam()["segments"] = n;
  s.force("tip", Vec3(-p * kEIy, 0, 0));
  s.j["loads"].back()["follows"] = follows;
  return s;
}

Model beck_column(int n, double p, bool follows) { return beck_scene(n, p, follows).model(); }

struct ColumnState {
  bool modal_ok = false;
  std::string message;  // the modal analysis's, when it failed
  int static_flutter = 0, static_negative = 0;
  double w1 = 0.0, w2 = 0.0;  // the two lowest frequencies along z, omega sqrt(m L^4 / EI)
};

// The equilibrium (straight, shortened) and the modes about it.
ColumnState column_state(int n, double p, bool follows) {
  const Model model = beck_column(n, p, follows);
  Data data(model);
  const StaticResult equilibrium = solve_static(model, StaticOptions{}, data);
  ColumnState out;
  out.static_flutter = equilibrium.flutter_pairs;
  out.static_negative = equilibrium.negative_directions;
  // Converged; unstable equilibria are reported as such (the modal analysis then says why).
  EXPECT_TRUE(equilibrium.ok || equilibrium.flutter_pairs > 0 ||
              equilibrium.negative_directions > 0)
      << equilibrium.message;
  ModalOptions options;
  options.modes = 3;
  const ModalResult modal = solve_modal(model, options, data);
  out.modal_ok = modal.ok;
  out.message = modal.message;
  if (!modal.ok) return out;
  const double scale = std::sqrt(kDensity * kArea / kEIy);
  std::vector<double> along_z;
  for (int k = 1; k <= 3; ++k) {
    const Mode* mode = elastic_mode(modal, k);
    double y = 0.0, z = 0.0;
    for (int i = 0; i < model.n_free(); ++i) {
      y += std::abs(mode->shape(6 * i + 1));
      z += std::abs(mode->shape(6 * i + 2));
    }
    if (z > 10 * y) along_z.push_back(2 * kPi * mode->frequency_hz * scale);
  }
  EXPECT_GE(along_z.size(), 2u) << "p = " << p;
  if (along_z.size() >= 2) out.w1 = along_z[0], out.w2 = along_z[1];
  return out;
}

// The load [EI/L^2] at which the modal analysis first fails, by bisection in [lo, hi] to 1e-7.
double critical_load(int n, bool follows, double lo, double hi) {
  EXPECT_TRUE(column_state(n, lo, follows).modal_ok);
  EXPECT_FALSE(column_state(n, hi, follows).modal_ok);
  while (hi - lo > 1e-7 * hi) {
    const double mid = 0.5 * (lo + hi);
    (column_state(n, mid, follows).modal_ok ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// Beck (1952): a cantilever under a tangential (follower) compressive tip force has no static
// buckling load; it loses stability by flutter at P = 20.05 EI/L^2, where its two lowest
// frequencies meet and turn into a complex pair. The modal analysis finds that load, converging
// to 20.05 at order 2 as the segments grow; the frequencies meet as the square root of the
// distance to it.
TEST(FollowerLoads, BecksColumnFluttersAt20EIOverL2) {
  constexpr double kBeck = 20.05;
  std::vector<double> errors, loads;
  for (int n : {4, 8, 16, 32, 64}) {
    const double flutter = critical_load(n, true, 10.0, 30.0);
    loads.push_back(flutter);
    errors.push_back(std::abs(flutter - kBeck) / kBeck);
    std::printf("Beck's column, %2d segments: flutter at P L^2 / EI = %.5f (%+.2f %% from 20.05)\n",
                n, flutter, 100 * (flutter - kBeck) / kBeck);
    // Just above: the modal analysis fails by flutter (complex pairs), and so does the static
    // analysis's stability check; no direction of negative stiffness (no divergence).
    const ColumnState above = column_state(n, flutter * (1 + 1e-5), true);
    EXPECT_NE(above.message.find("flutters"), std::string::npos) << above.message;
    EXPECT_GT(above.static_flutter, 0);
    EXPECT_EQ(above.static_negative, 0);
    if (n == 16) {
      // The two lowest frequencies approach each other: unloaded 3.516 and 22.03 (the
      // clamped-free beam's (beta L)^2), and their gap closes as sqrt(P_f - P).
      const ColumnState unloaded = column_state(n, 0.0, true);
      std::printf("  unloaded: omega sqrt(m L^4 / EI) = %.4f, %.4f\n", unloaded.w1, unloaded.w2);
      EXPECT_NEAR(unloaded.w1, 3.516, 0.01 * 3.516);
      EXPECT_NEAR(unloaded.w2, 22.03, 0.02 * 22.03);
      double gap[3];
      const double below[3] = {1e-2, 1e-4, 1e-6};
      for (int k = 0; k < 3; ++k) {
        const ColumnState near = column_state(n, flutter * (1 - below[k]), true);
        ASSERT_TRUE(near.modal_ok) << near.message;
        gap[k] = (near.w2 * near.w2 - near.w1 * near.w1) / (near.w2 * near.w2 + near.w1 * near.w1);
        std::printf("  at (1 - %.0e) P_f: omega = %.4f, %.4f (gap in omega^2 %.3e)\n", below[k],
                    near.w1, near.w2, gap[k]);
      }
      EXPECT_NEAR(gap[1] / gap[0], 0.1, 0.02);
      EXPECT_NEAR(gap[2] / gap[1], 0.1, 0.02);
    }
  }
  // Converging at order 2: 32 segments within 1 %, and the extrapolation from 32 and 64 within
  // the published value's own rounding (20.05).
  for (size_t k = 1; k < errors.size(); ++k) EXPECT_LT(errors[k], errors[k - 1]);
  const size_t last = loads.size() - 1;
  const double order =
      std::log2((loads[last - 2] - loads[last - 1]) / (loads[last - 1] - loads[last]));
  const double extrapolated = (4 * loads[last] - loads[last - 1]) / 3;
  std::printf("  observed order %.3f, extrapolated flutter load %.5f EI / L^2\n", order,
              extrapolated);
  EXPECT_NEAR(order, 2.0, 0.1);
  EXPECT_LT(errors[last - 1], 0.01);
  EXPECT_NEAR(extrapolated, kBeck, 0.005);
}

// The transient sees the same: the 8-segment column (flutter at 21.50 EI/L^2 above), its tip
// nudged sideways, vibrates with a bounded amplitude at 0.98 of the flutter load and with a
// growing one at 1.02 (bdf from the static equilibrium; the transient uses the forces, not the
// tangent's eigenvalues).
TEST(FollowerLoads, BecksColumnInATransientGrowsOnlyAboveTheFlutterLoad) {
  const double flutter = critical_load(8, true, 10.0, 30.0);
  for (double ratio : {0.98, 1.02}) {
    Scene s = beck_scene(8, ratio * flutter, true);
    s.j["bodies"][0]["velocity"] = vec(0, 0, 1e-5);
    const Model model = s.model();
    const int tip = body_index(model, "tip");
    TransientOptions options = testing::options(0.6, 1e-3, 1e-7, 1e-12);
    // From the shortened straight equilibrium (the static analysis reports it unstable above the
    // flutter load), so that no axial vibration starts with the load.
    Data equilibrium(model);
    const StaticResult st = solve_static(model, StaticOptions{}, equilibrium);
    ASSERT_EQ(st.flutter_pairs > 0, ratio > 1.0) << st.message;
    options.initial_state.resize(model.n_states);
    initial_state_at(model, equilibrium, options.initial_state.data());
    const testing::TransientRun run = testing::simulate(model, options);
    ASSERT_TRUE(run.result.ok) << run.result.message;
    double first = 0.0, last = 0.0;  // largest |z| of the tip in the first and the last 0.15 s
    for (const testing::Snapshot& snap : run.samples) {
      const double z = std::abs(snap.c[tip](2));
      if (snap.sample.t <= 0.15) first = std::max(first, z);
      if (snap.sample.t >= 0.45) last = std::max(last, z);
    }
    std::printf(
        "transient at %.2f P_f: tip amplitude %.3e m in the first 0.15 s, %.3e m in the "
        "last\n",
        ratio, first, last);
    if (ratio < 1.0) {
      EXPECT_LT(last, 2.0 * first);
      // The study default, auto (here the modal method, which integrates the symmetric part of
      // the tangent exactly and the rest, the follower's load stiffness among it, explicitly),
      // follows the same motion.
      TransientOptions automatic = options;
      automatic.integrator.method = IntegratorMethod::kAuto;
      automatic.integrator.rtol = 1e-6;
      automatic.integrator.atol = 1e-13;
      const testing::TransientRun other = testing::simulate(model, automatic);
      ASSERT_TRUE(other.result.ok) << other.result.message;
      double difference = 0.0;
      for (size_t k = 0; k < std::min(run.samples.size(), other.samples.size()); ++k)
        difference = std::max(difference, (other.samples[k].c[tip] - run.samples[k].c[tip]).norm());
      std::printf("  auto (rtol 1e-6) against bdf (1e-7): tip within %.2e of its amplitude\n",
                  difference / first);
      EXPECT_EQ(other.samples.size(), run.samples.size());
      EXPECT_LT(difference, 1e-4 * first);
    } else {
      EXPECT_GT(last, 10.0 * first);
    }
  }
}

// The same column under a compressive tip force of fixed direction buckles statically at Euler's
// pi^2/4 EI/L^2 = 2.467 (a frequency falls to zero): a direction of negative stiffness beyond
// it, no flutter. The buckling analysis agrees; it refuses the follower load (no buckling load).
TEST(FollowerLoads, BecksColumnUnderADeadLoadBucklesAtEulersLoad) {
  const double euler = kPi * kPi / 4;
  std::vector<double> errors;
  for (int n : {4, 8, 16, 32}) {
    const double critical = critical_load(n, false, 1.0, 4.0);
    errors.push_back(std::abs(critical - euler) / euler);
    std::printf("the dead load, %2d segments: buckles at P L^2 / EI = %.5f (%+.3f %% from %.5f)\n",
                n, critical, 100 * (critical - euler) / euler, euler);
    const ColumnState above = column_state(n, critical * (1 + 1e-5), false);
    EXPECT_NE(above.message.find("negative stiffness"), std::string::npos) << above.message;
    EXPECT_GT(above.static_negative, 0);
    EXPECT_EQ(above.static_flutter, 0);
  }
  for (size_t k = 1; k < errors.size(); ++k) EXPECT_LT(errors[k], errors[k - 1]);
  EXPECT_LT(errors.back(), 0.002);

  for (bool follows : {false, true}) {
    const Model model = beck_column(16, 1.0, follows);
    const Model reference = with_loads(
        model, [](const Load&) { return false; }, false);
    Data data(reference);
    const BucklingResult result = solve_buckling(reference, model, BucklingOptions{}, data);
    if (follows) {
      EXPECT_FALSE(result.ok);
      EXPECT_NE(result.message.find("a follower load is among the loads to scale"),
                std::string::npos)
          << result.message;
    } else {
      ASSERT_TRUE(result.ok) << result.message;
      const double factor = buckling_factor(result, 1);
      const double critical = critical_load(16, false, 1.0, 4.0);
      std::printf("buckling analysis, 16 segments: factor %.5f (the modal analysis: %.5f)\n",
                  factor, critical);
      EXPECT_NEAR(factor, critical, 1e-4 * factor);  // the column stays straight: both exact
    }
  }
  // A follower load held constant in the reference state makes its tangent non-symmetric: refused.
  const Model held = beck_column(16, 1.0, true), scaled = beck_column(16, 1.0, false);
  Data data(held);
  ASSERT_TRUE(solve_static(held, StaticOptions{}, data).ok);
  const BucklingResult result = solve_buckling(held, scaled, BucklingOptions{}, data);
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.message.find("torques of fixed direction or follower loads load it"),
            std::string::npos)
      << result.message;
}

// --- (d) Statics: an end moment and a tip force perpendicular to the tip -----------------------

// A cantilever along x (L = 1 m) in n segments, bending in the x-y plane about z (E Iz = 21 N m^2;
// Iy = 100 Iz out of the plane, and an axial stiffness 10^8 times E Iz / L^2: a strain of 2e-8
// under 2 EI / L^2, so the beam is as inextensible as the elastica it is compared with), a tip
// body without mass of its own, one tip load of value `value` (follower or not).
Model bent_cantilever(int n, const std::string& type, const Vec3& value, bool follows) {
  Scene s;
  s.material("steel", kE, kG, kDensity);
  s.custom("strip", 1e-2, 1e-8, 100 * kIy, kIy);
  s.j["bodies"].push_back({{"name", "tip"}, {"position", vec(1, 0, 0)}});
  s.beam("beam", "ground", "tip", Vec3::Zero(), Vec3(1, 0, 0), "steel", "strip");
  s.last_beam()["segments"] = n;
  s.j["loads"].push_back(
      {{"type", type}, {"body", "tip"}, {"value", vec(value(0), value(1), value(2))}});
  s.j["loads"].back()["follows"] = follows;
  return s.model();
}

// The tip of bent_cantilever(...) at its static equilibrium.
Vec3 bent_tip(int n, const std::string& type, const Vec3& value, bool follows) {
  const Model model = bent_cantilever(n, type, value, follows);
  Data data(model);
  const StaticResult result = solve_static(model, StaticOptions{}, data);
  EXPECT_TRUE(result.ok) << result.message;
  return centre(model, data, body_index(model, "tip"));
}

// An end moment M bends the cantilever into a circular arc of radius EI / M; here M L / EI = pi,
// a half circle with its tip at (0, 2 L / pi). A follower moment about the tip's own bending axis
// and a moment of fixed direction give the same arc in the plane; the segmented beam converges to
// it at order 2.
TEST(FollowerLoads, AnEndMomentBendsTheCantileverIntoACircle) {
  const double moment = kPi * kEIy;
  const Vec3 exact(0.0, 2.0 / kPi, 0.0);
  std::vector<double> errors;
  std::vector<Vec3> tips;
  for (int n : {8, 16, 32, 64}) {
    const Vec3 follower = bent_tip(n, "torque", Vec3(0, 0, moment), true);
    const Vec3 dead = bent_tip(n, "torque", Vec3(0, 0, moment), false);
    tips.push_back(follower);
    errors.push_back((follower - exact).norm());
    EXPECT_LT((follower - dead).norm(), 1e-9) << n;
    std::printf("end moment, %2d segments: tip (%.7f, %.7f, %.1e), error %.3e\n", n, follower(0),
                follower(1), follower(2), errors.back());
  }
  for (size_t k = 1; k < errors.size(); ++k) {
    const double order = std::log2(errors[k - 1] / errors[k]);
    std::printf("  observed order %.3f\n", order);
    EXPECT_NEAR(order, 2.0, 0.1);
  }
  EXPECT_LT(errors.back(), 1e-3);
  const Vec3 extrapolated = (4 * tips[3] - tips[2]) / 3;
  std::printf("  extrapolated from 32 and 64: error %.2e\n", (extrapolated - exact).norm());
  EXPECT_LT((extrapolated - exact).norm(), 1e-5);
}

// The full roll-up: M L / EI = 2 pi bends the cantilever into a whole circle, its tip back at the
// clamp and turned by a full turn, for a moment of fixed direction and a follower moment alike.
// Every segmented beam closes the circle exactly (its chords form a regular polygon), so the
// tip's distance from the clamp is rounding; the tip body's rotation, followed continuously
// through pi, is 2 pi. With automatic load steps (128 segments once stopped with "the loads push
// along a direction without stiffness").
TEST(FollowerLoads, AFullRollUpClosesTheCircle) {
  for (int n : {16, 128})
    for (bool follows : {true, false}) {
      const Model model = bent_cantilever(n, "torque", Vec3(0, 0, 2 * kPi * kEIy), follows);
      Data data(model);
      const StaticResult result = solve_static(model, StaticOptions{}, data);
      ASSERT_TRUE(result.ok) << n << ": " << result.message;
      const int tip = body_index(model, "tip");
      const Vec3 tip_point = centre(model, data, tip) +
                             data.pose[tip].A * (Vec3(1, 0, 0) - model.bodies[tip].position);
      std::printf(
          "roll-up, %3d segments, %s: tip %.1e m from the clamp, turned %.12f rad, %d load "
          "steps\n",
          n, follows ? "follower" : "fixed direction", tip_point.norm(), data.rotation[tip](2),
          result.load_steps);
      EXPECT_LT(tip_point.norm(), 1e-9);
      EXPECT_NEAR(data.rotation[tip](2), 2 * kPi, 1e-9);
    }
}

// The inextensible elastica under a tip force P that stays perpendicular to the tip: with the
// slope theta(s), EI theta'' = Fx sin theta - Fy cos theta, F = P (-sin theta_L, cos theta_L),
// theta(0) = 0, theta'(L) = 0. Shooting on theta_L (bisection), RK4 from the tip back to the
// clamp in 20,000 steps; the tip position by Simpson's rule over the same steps.
Vec3 perpendicular_elastica(double p) {  // p = P L^2 / EI, L = 1
  const int steps = 20000;
  const double h = 1.0 / steps;
  std::vector<double> theta(steps + 1);
  const auto shoot = [&](double tip) {
    const double fx = -p * std::sin(tip), fy = p * std::cos(tip);
    const auto rhs = [&](double th) { return fx * std::sin(th) - fy * std::cos(th); };
    double th = tip, dth = 0.0;  // at s = L, integrating towards s = 0
    theta[steps] = th;
    for (int k = steps; k > 0; --k) {
      const double k1t = -dth, k1d = -rhs(th);
      const double k2t = -(dth + 0.5 * h * k1d), k2d = -rhs(th + 0.5 * h * k1t);
      const double k3t = -(dth + 0.5 * h * k2d), k3d = -rhs(th + 0.5 * h * k2t);
      const double k4t = -(dth + h * k3d), k4d = -rhs(th + h * k3t);
      th += h / 6 * (k1t + 2 * k2t + 2 * k3t + k4t);
      dth += h / 6 * (k1d + 2 * k2d + 2 * k3d + k4d);
      theta[k - 1] = th;
    }
    return th;  // theta(0)
  };
  double lo = 0.0, hi = 3.0;
  EXPECT_LT(shoot(lo), 0.0);
  EXPECT_GT(shoot(hi), 0.0);
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (shoot(mid) < 0.0 ? lo : hi) = mid;
  }
  shoot(0.5 * (lo + hi));
  Vec3 tip = Vec3::Zero();
  for (int k = 0; k <= steps; ++k) {
    const double w = (k == 0 || k == steps) ? 1.0 : (k % 2 ? 4.0 : 2.0);
    tip += w * h / 3 * Vec3(std::cos(theta[k]), std::sin(theta[k]), 0.0);
  }
  return tip;
}

// A tip force that stays perpendicular to the tip (P L^2 / EI = 2), against the elastica above:
// order 2 in the segments; a force of the same size and fixed direction bends it far less.
TEST(FollowerLoads, ATipForcePerpendicularToTheTipFollowsTheElastica) {
  const double p = 2.0;
  const Vec3 exact = perpendicular_elastica(p);
  std::printf("perpendicular follower force, P L^2 / EI = %.0f: elastica tip (%.7f, %.7f)\n", p,
              exact(0), exact(1));
  std::vector<double> errors;
  std::vector<Vec3> tips;
  for (int n : {8, 16, 32, 64}) {
    const Vec3 tip = bent_tip(n, "force", Vec3(0, p * kEIy, 0), true);
    tips.push_back(tip);
    errors.push_back((tip - exact).norm());
    std::printf("  %2d segments: tip (%.7f, %.7f, %.1e), error %.3e\n", n, tip(0), tip(1), tip(2),
                errors.back());
  }
  for (size_t k = 1; k < errors.size(); ++k) {
    const double order = std::log2(errors[k - 1] / errors[k]);
    std::printf("  observed order %.3f\n", order);
    EXPECT_NEAR(order, 2.0, 0.15);
  }
  EXPECT_LT(errors.back(), 1e-4);
  const Vec3 extrapolated = (4 * tips[3] - tips[2]) / 3;
  std::printf("  extrapolated from 32 and 64: error %.2e\n", (extrapolated - exact).norm());
  EXPECT_LT((extrapolated - exact).norm(), 2e-6);
  // The dead force's elastica (docs/model.md "Validation": tip deflection 0.4934575 L at 2).
  const Vec3 dead = bent_tip(64, "force", Vec3(0, p * kEIy, 0), false);
  EXPECT_NEAR(dead(1), 0.4934575, 1e-4);
  EXPECT_GT(exact(1) - dead(1), 0.05);
}

// The static design sensitivity under a follower load: du/dp = -S^-1 dW/dp with S the exact
// tangent, its non-symmetric load stiffness included, against central differences of whole
// static analyses (extrapolated), for p = E.
TEST(FollowerLoads, StaticSensitivityUnderAFollowerForceMatchesDifferences) {
  const auto model_at = [](double e) {
    Scene s;
    s.material("steel", e, kG, kDensity);
    s.custom("strip", 1e-2, 1e-8, 100 * kIy, kIy);
    s.j["bodies"].push_back({{"name", "tip"}, {"position", vec(1, 0, 0)}});
    s.beam("beam", "ground", "tip", Vec3::Zero(), Vec3(1, 0, 0), "steel", "strip");
    s.last_beam()["segments"] = 8;
    s.force("tip", Vec3(0, 2 * kEIy, 0));
    s.j["loads"].back()["follows"] = true;
    return s.model();
  };
  const auto tip_at = [&](double e) {
    const Model m = model_at(e);
    Data d(m);
    const StaticResult r = solve_static(m, StaticOptions{}, d);
    EXPECT_TRUE(r.ok) << r.message;
    return centre(m, d, body_index(m, "tip"));
  };
  const Model model = model_at(kE);
  Data data(model);
  ASSERT_TRUE(solve_static(model, StaticOptions{}, data).ok);
  const double h = 1e-4 * kE;
  const Model plus = model_at(kE + h), minus = model_at(kE - h);
  const double t = std::numeric_limits<double>::infinity();
  const EquilibriumSensitivity sensitivity(model, data, t);
  ASSERT_EQ(sensitivity.failure(), "");
  const DualModel direction = design_direction(model, plus, minus, h);
  const Eigen::VectorXd du = sensitivity.state_derivative({&direction});
  const int k = model.bodies[body_index(model, "tip")].free_index;
  const Vec3 exact = du.segment<3>(6 * k);
  const auto difference = [&](double step) {
    return Vec3((tip_at(kE + step) - tip_at(kE - step)) / (2 * step));
  };
  const Vec3 fd = (4 * difference(1e-3 * kE) - difference(2e-3 * kE)) / 3;
  std::printf("d tip / dE: exact (%.9e, %.9e), differences (%.9e, %.9e)\n", exact(0), exact(1),
              fd(0), fd(1));
  EXPECT_LT((exact - fd).norm(), 1e-6 * fd.norm());
}

}  // namespace
}  // namespace beamrail
