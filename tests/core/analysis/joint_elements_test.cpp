// Joints as elements in every analysis (docs/model.md "Joints"): a body clamped by a fixed joint is
// held as by a beam (the static solver and the modal shift treat it so); a spherical or revolute
// joint leaves a mechanism (a pendulum); a mode that strains a joint's penalty is elastic, a
// mechanism's swing is rigid. Checked against closed forms: the cantilever's P L^3 / 3 EI, the
// two-degree-of-freedom tip mass on a massless beam, and the penalty modes of a body on a joint
// (its stiffness k_f, k_m on the body's mass and inertia).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/static_analysis.hpp"
#include "core/model/forces.hpp"
#include "tests/support/scene_builder.hpp"

namespace beamrail {
namespace {

using testing::body_index;
using testing::joint;
using testing::Scene;
using testing::vec;
constexpr double kE = 2.1e11, kG = 8.0e10, kDensity = 7850.0, kSide = 0.01;
constexpr double kEI = kE * kSide * kSide * kSide * kSide / 12;

bool has_warning(const std::vector<std::string>& warnings, const std::string& part) {
  return std::any_of(warnings.begin(), warnings.end(),
                     [&](const std::string& w) { return w.find(part) != std::string::npos; });
}

// --- Which joints hold a body -------------------------------------------------------------------

// ground -(joint of `type`)- a -beam- b
Model held_scene(const std::string& type) {
  Scene s;
  s.material("steel", kE, kG, kDensity);
  s.square("bar", kSide);
  s.body("a", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(0, 0, 0));
  s.body("b", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(1, 0, 0));
  s.beam("bar", "a", "b", Vec3::Zero(), Vec3(1, 0, 0), "steel", "bar");
  s.j["joints"] = Json::array({joint("j", type, "ground", "a", Vec3::Zero())});
  if (type == "revolute") s.j["joints"][0]["axis"] = vec(0, 0, 1);
  return s.model();
}

TEST(JointElements, AFixedJointHoldsABodyAsABeamDoesASphericalOrRevoluteOneDoesNot) {
  EXPECT_TRUE(held_by_beams(held_scene("fixed")));
  EXPECT_FALSE(held_by_beams(held_scene("revolute")));
  EXPECT_FALSE(held_by_beams(held_scene("spherical")));
}

// --- (1) A long cantilever clamped by fixed joints ----------------------------------------------

// A 1 m steel cantilever of 10 mm square section along x in `n` segments, loaded at its tip by
// -p along y; clamped to ground directly, or by a fixed joint at its root body (and, with
// `split`, in two halves of n / 2 segments that a second fixed joint holds together at x = 0.5).
struct Cantilever {
  StaticResult result;
  double deflection = 0.0;  // tip, -u_y [m]
};

Cantilever cantilever(int n, bool jointed, bool split, double p) {
  Scene s;
  s.material("steel", kE, kG, kDensity);
  s.square("bar", kSide);
  if (jointed) s.body("root", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(0, 0, 0));
  if (split) {
    s.body("left", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(0.5, 0, 0));
    s.body("right", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(0.5, 0, 0));
  }
  s.body("tip", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(1, 0, 0));
  const std::string base = jointed ? "root" : "ground";
  if (split) {
    s.beam("first", base, "left", Vec3::Zero(), Vec3(0.5, 0, 0), "steel", "bar");
    s.last_beam()["segments"] = n / 2;
    s.beam("second", "right", "tip", Vec3(0.5, 0, 0), Vec3(1, 0, 0), "steel", "bar");
    s.last_beam()["segments"] = n / 2;
  } else {
    s.beam("bar", base, "tip", Vec3::Zero(), Vec3(1, 0, 0), "steel", "bar");
    s.last_beam()["segments"] = n;
  }
  s.j["joints"] = Json::array();
  if (jointed) s.j["joints"].push_back(joint("clamp", "fixed", "ground", "root", Vec3::Zero()));
  if (split) s.j["joints"].push_back(joint("weld", "fixed", "left", "right", Vec3(0.5, 0, 0)));
  s.force("tip", Vec3(0, -p, 0));
  const Model model = s.model();
  Data data(model);
  Cantilever out;
  out.result = solve_static(model, StaticOptions{}, data);
  out.deflection = -data.pose[body_index(model, "tip")].u(1);
  return out;
}

// 600 segments (3,606 degrees of freedom, above the dense fallback's 3,000): the tangent's pivots
// span 1 / (4 n^3) ~ 1e-9 of each other, below the 1e-8 floor of a scene that may be a mechanism.
// Before fixed joints counted as holding, the clamped-by-a-joint cantilever failed ("the tangent
// stiffness is singular: a body or mechanism is free to move", at load factor 1e-6).
TEST(JointElements, ALongCantileverClampedByFixedJointsDeflectsByPL3Over3EI) {
  const double p = 0.1, exact = p / (3 * kEI);  // L = 1 m; deflection / L = 1.9e-4
  const Cantilever clamped = cantilever(600, false, false, p);
  ASSERT_TRUE(clamped.result.ok) << clamped.result.message;
  for (bool split : {false, true}) {
    const Cantilever c = cantilever(600, true, split, p);
    ASSERT_TRUE(c.result.ok) << c.result.message;
    const double error = (c.deflection - exact) / exact;
    const double joints = (c.deflection - clamped.deflection) / exact;
    std::printf(
        "600 segments clamped by a fixed joint%s: tip deflection %.10e m, P L^3 / 3 EI %.10e "
        "(%+.2e; clamped directly %+.2e), the joints add %+.2e; %d Newton iterations\n",
        split ? " and welded at mid-span by another" : "", c.deflection, exact, error,
        (clamped.deflection - exact) / exact, joints, c.result.iterations);
    // The geometric nonlinearity at deflection / L = 1.9e-4 is ~(1.9e-4)^2 = 3.6e-8; the joints
    // give way by at most their relative compliance (1e-6) of it.
    EXPECT_LT(std::abs(error), 1e-7);
    EXPECT_LT(std::abs(joints), 1e-6);
    EXPECT_EQ(c.result.singular_directions, 0);
  }
}

// A bob hung on a revolute joint (about z, the default relative compliance 1e-6) from the tip of a
// massless 1 m cantilever, under gravity: the tip sinks by (M + m) g L^3 / 3 EI, the bob's weight
// passing through the joint point (no moment). The first Newton iterate meets the swing without
// stiffness (the joint carries no tension yet) and solves minimum-norm; that solve leaves 6e-6 of
// the forces, rounding of a tangent whose penalty spans 1e11 of the beam's stiffness (eps |S| |dx|
// is three times as much). The static solver used to read that as the loads pushing along the
// swing and refused: "there is no equilibrium" (measured on this scene with a 12 x 10 mm section;
// it passed at relative compliance 1e-5 and above).
TEST(JointElements, ABobHungOnARevoluteJointFromACantileverTipLoadsItWithItsWeight) {
  const double m_tip = 1.0, m_bob = 0.5, g = 9.81;
  Scene s;
  s.material("steel", kE, kG);
  s.square("bar", kSide);
  s.j["gravity"] = vec(0, -g, 0);
  s.body("tip", m_tip, Vec3(1e-4, 1e-4, 1e-4), Vec3(1, 0, 0));
  s.body("bob", m_bob, Vec3(1e-3, 1e-3, 1e-3), Vec3(1, -0.2, 0));
  s.beam("arm", "ground", "tip", Vec3::Zero(), Vec3(1, 0, 0), "steel", "bar");
  s.j["joints"] = Json::array({joint("hinge", "revolute", "tip", "bob", Vec3(1, 0, 0))});
  s.j["joints"][0]["axis"] = vec(0, 0, 1);
  const Model model = s.model();
  Data data(model);
  const StaticResult r = solve_static(model, StaticOptions{}, data);
  ASSERT_TRUE(r.ok) << r.message;
  const double sag = -data.pose[body_index(model, "tip")].u(1);
  const double exact = (m_tip + m_bob) * g / (3 * kEI);
  const double bob_sag = -data.pose[body_index(model, "bob")].u(1);
  std::printf(
      "bob on a revolute joint at a cantilever tip: tip sag %.10e m ((M + m) g L^3 / 3 EI "
      "%.10e, %+.2e), the bob sinks with it to %.2e; %d Newton iterations\n",
      sag, exact, sag / exact - 1, (bob_sag - sag) / sag, r.iterations);
  // Measured -8.9e-12; the geometric nonlinearity could reach ~(sag / L)^2 = 8e-4.
  EXPECT_LT(std::abs(sag / exact - 1), 1e-3);
  // The bob follows the joint point, which the tip's turn moves by 0 along y: the joint's stretch
  // (c of the lever) and the bob's own swing (none: its weight passes through the joint) only.
  EXPECT_LT(std::abs(bob_sag - sag), 1e-5 * sag);
}

// A pendulum released off the vertical: its unloaded joint gives the swing no stiffness at the
// start, and gravity pushes along the swing, so the first Newton iterate solves minimum-norm and
// leaves a push along its null direction; the iterate loads the joint, whose tension then holds
// the swing. The static solver refused at the first push ("there is no equilibrium", at every
// tilt from 0.5 degrees); now it goes on while the push falls and finds the hanging equilibrium:
// the bob's centre straight below the joint at its distance d, turned back by the tilt. A
// carriage pushed along its rail (rail_static_test.cpp) is still refused. (On a spherical joint
// the push falls too, but the minimum-norm corrections then turn the bob about the vertical, its
// free direction, by rounding, and the solver stops as rounding-limited: left as it was.)
TEST(JointElements, APendulumReleasedOffTheVerticalFindsItsHangingEquilibrium) {
  const double d = 0.4, m = 3.0, g = 9.81;
  for (const double degrees : {5.0, 30.0, 60.0, 89.0}) {
    const double tilt = degrees * std::numbers::pi / 180.0;
    Scene s;
    s.j["gravity"] = vec(0, 0, -g);
    s.body("bob", m, Vec3(0.02, 0.05, 0.06), Vec3(d * std::sin(tilt), 0, -d * std::cos(tilt)));
    s.j["joints"] = Json::array({joint("j", "revolute", "ground", "bob", Vec3::Zero())});
    s.j["joints"][0]["axis"] = vec(0, 1, 0);
    const Model model = s.model();
    Data data(model);
    const StaticResult r = solve_static(model, StaticOptions{}, data);
    ASSERT_TRUE(r.ok) << degrees << " degrees: " << r.message;
    const Pose<double>& pose = data.pose[body_index(model, "bob")];
    const Vec3 centre = model.bodies[body_index(model, "bob")].position + pose.u;
    const Eigen::AngleAxisd turn(pose.A);
    std::printf(
        "pendulum tilted %g degrees: centre (%.3e, %.3e, %.9f) m, turned %.9f rad, %d "
        "Newton iterations, %zu warnings\n",
        degrees, centre.x(), centre.y(), centre.z(), turn.angle(), r.iterations, r.warnings.size());
    // The joint's penalty (the default relative compliance 1e-6) gives way under m g by 1e-6 of
    // d here: measured 4.0e-7 m.
    EXPECT_LT(std::abs(centre.x()), 1e-9);
    EXPECT_LT(std::abs(centre.z() + d), 2e-6 * d);
    EXPECT_NEAR(turn.angle(), tilt, 1e-9);
    // The equilibrium has no direction without stiffness: no warning of a free mechanism.
    EXPECT_FALSE(has_warning(r.warnings, "without stiffness")) << r.warnings.front();
  }
}

// --- (2) Modes held by joints -------------------------------------------------------------------

// The eigenvalues of the 2 x 2 problem K x = w^2 diag(m1, m2) x, ascending.
std::pair<double, double> two_by_two(double k11, double k12, double k22, double m1, double m2) {
  const double a = k11 / m1, d = k22 / m2, b = k12 * k12 / (m1 * m2);
  const double mean = 0.5 * (a + d), root = std::sqrt(0.25 * (a - d) * (a - d) + b);
  return {mean - root, mean + root};
}

// A tip body (mass M, inertia J) on one massless beam whose root body a fixed joint clamps: every
// body held, so the modal shift is 0 and the lowest modes are the beam's, each plane's lower
// eigenvalue of [12 EI/L^3, -6 EI/L^2; -6 EI/L^2, 4 EI/L] on diag(M, J).
TEST(JointElements, ATipMassOnABeamClampedByAFixedJointVibratesAsClamped) {
  const double mass = 2.0, j = 1e-3, l = 1.0;
  Scene s;
  s.material("steel", kE, kG);  // massless
  s.square("bar", kSide);
  s.body("root", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(0, 0, 0));
  s.body("tip", mass, Vec3(j, j, j), Vec3(l, 0, 0));
  s.beam("bar", "root", "tip", Vec3::Zero(), Vec3(l, 0, 0), "steel", "bar");
  s.j["joints"] = Json::array({joint("clamp", "fixed", "ground", "root", Vec3::Zero())});
  const Model model = s.model();
  Data data(model);
  ModalOptions options;
  options.modes = 2;
  const ModalResult r = solve_modal(model, options, data);
  ASSERT_TRUE(r.ok) << r.message;
  const double exact =
      two_by_two(12 * kEI / (l * l * l), -6 * kEI / (l * l), 4 * kEI / l, mass, j).first;
  EXPECT_EQ(r.shift, 0.0);
  EXPECT_EQ(r.rigid_modes, 0);
  EXPECT_FALSE(has_warning(r.warnings, "deform joints"));
  for (int k = 1; k <= 2; ++k) {
    const Mode* mode = elastic_mode(r, k);
    ASSERT_NE(mode, nullptr);
    const double error = (mode->eigenvalue - exact) / exact;
    std::printf(
        "tip mass on a beam clamped by a fixed joint, mode %d: w^2 = %.10e (exact %.10e, %+.2e)\n",
        k, mode->eigenvalue, exact, error);
    EXPECT_LT(std::abs(error), 1e-5);  // the clamp gives way by ~1e-6 of the beam
  }
}

// A rod-like body (m = 1 kg, centre d = 0.5 m below the joint, I_c = m (2d)^2 / 12 about each
// axis) on a joint at the origin.
constexpr double kM = 1.0, kD = 0.5, kIc = kM * 4 * kD * kD / 12;

Model rod_on(const std::string& type, double g) {
  Scene s;
  if (g != 0.0) s.j["gravity"] = vec(0, -g, 0);
  s.body("rod", kM, Vec3(kIc, kIc, kIc), Vec3(0, -kD, 0));
  s.j["joints"] = Json::array({joint("pivot", type, "ground", "rod", Vec3::Zero())});
  if (type == "revolute") s.j["joints"][0]["axis"] = vec(0, 0, 1);
  return s.model();
}

// Sorted eigenvalues of the elastic modes.
std::vector<double> elastic_eigenvalues(const ModalResult& r) {
  std::vector<double> out;
  for (const Mode& m : r.modes)
    if (m.kind != Mode::Kind::kRigid) out.push_back(m.eigenvalue);
  std::sort(out.begin(), out.end());
  return out;
}

// Weightless, on a spherical joint: no stiffness against turning about the joint (three rigid
// modes at w^2 = 0; the scene is not held: a shifted problem) and three penalty modes: the
// stretch along the rod at k_f / m, across it at k_f (1/m + d^2 / I_c) (twice).
TEST(JointElements, AWeightlessBodyOnASphericalJointTurnsFreelyAndVibratesOnThePenalty) {
  const Model model = rod_on("spherical", 0.0);
  Data data(model);
  ModalOptions options;
  options.modes = 3;
  const ModalResult r = solve_modal(model, options, data);
  ASSERT_TRUE(r.ok) << r.message;
  const double k = model.joints[0].k_force;
  EXPECT_GT(r.shift, 0.0);
  EXPECT_EQ(r.rigid_modes, 3);
  const std::vector<double> elastic = elastic_eigenvalues(r);
  ASSERT_EQ(elastic.size(), 3u);
  // Rigid: w^2 = 0 up to the rounding of the stiffness, ~eps lambda_max.
  for (const Mode& m : r.modes) {
    if (m.kind == Mode::Kind::kRigid) {
      EXPECT_LT(std::abs(m.eigenvalue), 1e3 * 2.2e-16 * elastic[2]);
    }
  }
  const double exact[3] = {k / kM, k * (1 / kM + kD * kD / kIc), k * (1 / kM + kD * kD / kIc)};
  for (int i = 0; i < 3; ++i) {
    std::printf("spherical joint, penalty mode %d: w^2 = %.10e (exact %.10e, %+.2e)\n", i + 1,
                elastic[i], exact[i], elastic[i] / exact[i] - 1);
    EXPECT_NEAR(elastic[i] / exact[i], 1.0, 1e-9);
  }
  EXPECT_TRUE(has_warning(r.warnings, "3 elastic mode(s) deform joints and no beam or rail"));
}

// Hanging under gravity on a revolute joint about z: the swing is the one rigid mode (a mechanism
// the joint allows), w^2 = m g d / I_O; the joint's five penalty modes are elastic, far above:
// the stretch along the rod k_f / m, the spin about the rod k_m / I_c, across the rod in the
// swing plane k_f (1/m + d^2 / I_c), and out of it the 2 x 2 of (z, rotation about x) with
// stiffness [k_f, -k_f d; -k_f d, k_f d^2 + k_m] on diag(m, I_c). The joint's tension m g adds
// terms of relative size ~c = 1e-6 to the penalty modes.
TEST(JointElements, AHangingRodOnARevoluteJointSwingsAsAMechanismAboveItsPenaltyModes) {
  const double g = 9.81;
  const Model model = rod_on("revolute", g);
  Data data(model);
  const StaticResult equilibrium = solve_static(model, StaticOptions{}, data);
  ASSERT_TRUE(equilibrium.ok) << equilibrium.message;
  ModalOptions options;
  options.modes = 5;
  const ModalResult r = solve_modal(model, options, data);
  ASSERT_TRUE(r.ok) << r.message;
  ASSERT_EQ(r.rigid_modes, 1);
  const Mode& swing = r.modes[0];
  EXPECT_EQ(swing.kind, Mode::Kind::kRigid);
  const double swing_exact = kM * g * kD / (kIc + kM * kD * kD);
  std::printf("revolute joint: swing w^2 = %.10e (exact %.10e, %+.2e), classed %s\n",
              swing.eigenvalue, swing_exact, swing.eigenvalue / swing_exact - 1,
              swing.kind == Mode::Kind::kRigid ? "rigid" : "elastic");
  EXPECT_NEAR(swing.eigenvalue / swing_exact, 1.0, 1e-5);
  const double kf = model.joints[0].k_force, km = model.joints[0].k_moment;
  const auto [out_low, out_high] = two_by_two(kf, -kf * kD, kf * kD * kD + km, kM, kIc);
  std::vector<double> exact = {kf / kM, km / kIc, kf * (1 / kM + kD * kD / kIc), out_low, out_high};
  std::sort(exact.begin(), exact.end());
  const std::vector<double> elastic = elastic_eigenvalues(r);
  ASSERT_EQ(elastic.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    std::printf("revolute joint, penalty mode %d: w^2 = %.10e (exact %.10e, %+.2e)\n", i + 1,
                elastic[i], exact[i], elastic[i] / exact[i] - 1);
    EXPECT_NEAR(elastic[i] / exact[i], 1.0, 1e-5);
    EXPECT_GT(elastic[i], 1e5 * swing_exact);
  }
  EXPECT_TRUE(has_warning(r.warnings, "5 elastic mode(s) deform joints and no beam or rail"));
}

// --- Rounding far from the origin ---------------------------------------------------------------

// A joint's gap is the difference of its two points' displacements, not of their positions: a
// joint between the ground and a body 100 .. 1,000 m from the origin carries exactly nothing at
// rest, and a body moved by 1 nm is pulled back by k_f times 1 nm to rounding (taken from
// positions, the gap carried their rounding, 1e-14 m, which made k_f 1e-14 m forces of noise: 1e-5
// of this one; a pinned frame of 160 segments stalled on it, tests/core/analysis/lee_frame_test).
TEST(JointElements, AJointFarFromTheOriginHoldsExactlyNothingAtRest) {
  const double du = 1e-9;
  double worst_rest = 0.0, worst_pull = 0.0;
  for (int k = 0; k < 20; ++k) {
    const double far = 100.0 + 47.3 * k;
    const Vec3 centre(far, 0.7 * far + 0.123, -0.31 * far), point = centre + Vec3(0.3, -0.11, 0.07);
    Scene s;
    s.material("steel", kE, kG, kDensity).square("sq", kSide);
    s.body("b", 1.0, Vec3(1e-3, 1e-3, 1e-3), centre);
    s.j["joints"] = Json::array({joint("pin", "spherical", "ground", "b", point)});
    const Model model = s.model();
    Data data(model);
    const int b = body_index(model, "b");
    compute_wrenches(model, data, 0.0);
    worst_rest = std::max(worst_rest, data.wrench[b].norm());
    data.pose[b].u = Vec3(du, -du, 0.5 * du);
    compute_wrenches(model, data, 0.0);
    const Vec3 expected = -model.joints[0].k_force * data.pose[b].u;
    worst_pull =
        std::max(worst_pull, (data.wrench[b].head<3>() - expected).norm() / expected.norm());
  }
  std::printf("joints 100 .. 1,000 m away: force at rest %.1e N; pull of a 1 nm move off by %.1e\n",
              worst_rest, worst_pull);
  EXPECT_EQ(worst_rest, 0.0);
  EXPECT_LT(worst_pull, 1e-14);
}

// A joint's rotational energy for a tiny turn across its axis is k_moment (1 - cos theta) =
// 2 k_moment sin^2(theta / 2) to rounding: summed as 1 - a1.a2, a1.a2 rounded to steps of 1.1e-16
// near 1, which a joint of relative compliance 1e-9 made steps of 6.5e-7 J (the energy check then
// reported a bob swinging 1 degree on it as 0.0015 of its energy off, even for an explicit run at
// rtol 1e-12). A body on a revolute or fixed joint at its centre (no lever: no gap), turned by
// 1e-9 .. 1e-5 rad about an axis across the joint's: summed as 1 - a1.a2 it was off by 1.0 (0
// below 1e-8 rad); now by 3e-16.
TEST(JointElements, AStiffJointsEnergyOfATinyTurnIsItsClosedForm) {
  for (const std::string type : {"revolute", "fixed"}) {
    Scene s;
    s.material("steel", kE, kG, kDensity).square("sq", kSide);
    s.body("b", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(0.2, -0.3, 0.1));
    Json j = joint("pin", type, "ground", "b", Vec3(0.2, -0.3, 0.1));
    if (type == "revolute") j["axis"] = vec(0, 0, 1);
    j["relative_compliance"] = 1e-9;
    s.j["joints"] = Json::array({j});
    const Model model = s.model();
    Data data(model);
    const int b = body_index(model, "b");
    double worst = 0.0;
    for (const double theta : {1e-9, 1e-8, 1e-7, 1e-6, 1e-5}) {
      data.pose[b].A = Eigen::AngleAxisd(theta, Vec3(0.6, 0.8, 0.0)).toRotationMatrix();
      compute_wrenches(model, data, 0.0);
      const double sine = std::sin(0.5 * theta);
      const double expected = 2.0 * model.joints[0].k_moment * sine * sine;
      worst = std::max(worst, std::abs(data.elastic_energy - expected) / expected);
    }
    std::printf("%s joint, k_moment %.2e N m: energy of turns 1e-9 .. 1e-5 rad off by %.1e\n",
                type.c_str(), model.joints[0].k_moment, worst);
    EXPECT_LT(worst, 1e-6);
  }
}

}  // namespace
}  // namespace beamrail
