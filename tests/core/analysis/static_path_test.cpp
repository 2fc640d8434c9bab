// Arc-length control of the static analysis (core/analysis/static_path.cpp) against closed forms:
// a shallow two-bar truss (von Mises truss) snapping through under an apex load, whose
// load-displacement curve is known exactly, and a cantilever whose path has no limit point.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "core/analysis/static_analysis.hpp"
#include "tests/support/scene_builder.hpp"

namespace beamrail {
namespace {

using testing::body_index;
using testing::Scene;
using testing::vec;

// Two bars of axial stiffness EA pinned (revolute joints about z) to ground at (-a, 0) and (a, 0)
// and to each other at the apex (0, h). Pushed down by w, each bar has length L = sqrt(a^2 + (h -
// w)^2) and compression N = EA (L0 - L) / L0, and the apex load in equilibrium is
//   P(w) = 2 N (h - w) / L,
// which rises to a limit at w1, falls through 0 at w = h (the bars in line) to -P(w1) at 2h - w1,
// and rises again beyond: under a load above P(w1) the truss snaps through to the inverted branch.
constexpr double kA = 1.0, kH = 0.1, kEA = 1e6;

double truss_load(double w) {
  const double l0 = std::hypot(kA, kH), l = std::hypot(kA, kH - w);
  return 2.0 * kEA * (l0 - l) / l0 * (kH - w) / l;
}

// The largest of P on [0, h] (golden section: P is unimodal there).
double truss_limit_load() {
  double lo = 0.0, hi = kH;
  const double g = (std::sqrt(5.0) - 1.0) / 2.0;
  for (int k = 0; k < 200; ++k) {
    const double m1 = hi - g * (hi - lo), m2 = lo + g * (hi - lo);
    (truss_load(m1) < truss_load(m2) ? lo : hi) = truss_load(m1) < truss_load(m2) ? m1 : m2;
  }
  return truss_load(0.5 * (lo + hi));
}

// The w > h where P(w) = p on the inverted branch (P rises monotonically beyond 2h - w1).
double inverted_deflection(double p) {
  double lo = kH, hi = 10.0 * kH;
  while (truss_load(hi) < p) hi *= 2.0;
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    (truss_load(mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

Json pin(const std::string& name, const std::string& b1, const std::string& b2, const Vec3& p) {
  Json j = testing::joint(name, "revolute", b1, b2, p);
  j["axis"] = vec(0, 0, 1);
  return j;
}

Model von_mises_truss(double p) {
  Scene s;
  s.material("steel", 2.1e11, 8.1e10);
  const double area = kEA / 2.1e11;
  // Stiff in bending (the bars' own Euler load, 2e6 N, far above their largest compression, 5e3
  // N at w = h): the bars stay straight.
  s.custom("bar", area, 1e-6, 1e-6, 1e-6);
  const Vec3 apex(0, kH, 0), left(-kA, 0, 0), right(kA, 0, 0);
  const Vec3 inertia(1e-3, 1e-3, 1e-3);
  s.body("left_foot", 1.0, inertia, left).body("apex", 1.0, inertia, apex);
  s.body("right_head", 1.0, inertia, apex).body("right_foot", 1.0, inertia, right);
  // The left bar ends in the apex body itself (one pin at the apex: a second would leave the apex
  // body free to spin about it).
  s.beam("left_bar", "left_foot", "apex", left, apex, "steel", "bar");
  s.beam("right_bar", "right_foot", "right_head", right, apex, "steel", "bar");
  s.j["joints"] = Json::array({pin("left_pin", "ground", "left_foot", left),
                               pin("apex_pin", "apex", "right_head", apex),
                               pin("right_pin", "right_foot", "ground", right)});
  s.force("apex", Vec3(0, -p, 0));
  return s.model();
}

TEST(StaticPath, VonMisesTrussSnapsThroughAlongItsClosedForm) {
  const double limit = truss_limit_load();
  const double p = 1.5 * limit;
  const Model model = von_mises_truss(p);
  const int apex = body_index(model, "apex");
  StaticOptions options;
  options.control = StaticControl::kArcLength;
  Data data(model);
  const StaticResult r = solve_static(model, options, data);
  ASSERT_TRUE(r.ok) << r.message;
  // The path records the scene's bodies; the apex among them.
  int column = -1;
  for (size_t k = 0; k < r.path_bodies.size(); ++k)
    if (r.path_bodies[k] == apex) column = static_cast<int>(k);
  ASSERT_GE(column, 0);
  // Every point on the closed-form curve; the apex goes straight down (symmetry).
  double worst = 0.0, lowest = 0.0, sideways = 0.0;
  for (const StaticPathPoint& point : r.path) {
    const double w = -point.displacement[column](1);
    worst = std::max(worst, std::abs(point.load_factor * p - truss_load(w)) / limit);
    lowest = std::min(lowest, point.load_factor);
    sideways = std::max(sideways, std::abs(point.displacement[column](0)));
  }
  const double w_end = -data.pose[apex].u(1), w_exact = inverted_deflection(p);
  std::printf(
      "von Mises truss, P = 1.5 P_limit: %zu path points, %d steps, %d iterations; load off the "
      "closed form by at most %.2e P_limit; limit load factor %.8f (exact %.8f, %+.2e); lowest "
      "load factor %.6f (exact %.6f); final deflection %.8f m (exact %.8f, %+.2e); sideways %.1e "
      "m\n",
      r.path.size(), r.load_steps, r.iterations, worst, r.limit_load_factor, limit / p,
      r.limit_load_factor - limit / p, lowest, -limit / p, w_end, w_exact, w_end - w_exact,
      sideways);
  // The joints' penalty (relative compliance 1e-6, the default: docs/model.md "Joints") lengthens
  // the bars by about 1e-6 of their stretch per joint, up to two per bar.
  EXPECT_LT(worst, 5e-6);
  // The limit from a parabola through the highest point and its neighbours.
  EXPECT_NEAR(r.limit_load_factor, limit / p, 1e-4 * limit / p);
  // The path passed the second limit point (the bars in line and beyond).
  EXPECT_LT(lowest, -0.9 * limit / p);
  EXPECT_NEAR(w_end, w_exact, 5e-6 * w_exact);
  EXPECT_LT(sideways, 1e-6 * kH);  // the bars' joints differ in number: see above
  EXPECT_GT(r.path.size(), 10u);
}

TEST(StaticPath, VonMisesTrussBelowItsLimitStopsAtTheFullLoadOnTheFirstBranch) {
  const double limit = truss_limit_load();
  const Model model = von_mises_truss(0.6 * limit);
  StaticOptions options;
  options.control = StaticControl::kArcLength;
  Data data(model);
  const StaticResult r = solve_static(model, options, data);
  ASSERT_TRUE(r.ok) << r.message;
  const double w = -data.pose[body_index(model, "apex")].u(1);
  // The root of P(w) = 0.6 P_limit below the limit point.
  double lo = 0.0, hi = kH;
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    (truss_load(mid) < 0.6 * limit && mid < 0.5 * kH ? lo : hi) = mid;
  }
  std::printf("von Mises truss, P = 0.6 P_limit: deflection %.9f m (exact %.9f), %zu points\n", w,
              lo, r.path.size());
  EXPECT_NEAR(w, lo, 5e-6 * lo);  // the joints' compliance, as above
  EXPECT_TRUE(std::isnan(r.limit_load_factor));
  EXPECT_DOUBLE_EQ(r.path.back().load_factor, 1.0);
}

TEST(StaticPath, CantileverPathEndsAtTheLoadControlledEquilibrium) {
  // A steel cantilever (1 m, 10 mm square, 8 segments) under a tip force bending it by ~40 %
  // of its length: no limit point; arc length and load steps reach the same equilibrium.
  Scene s;
  s.material("steel", 2.1e11, 8.1e10, 7850.0);
  s.square("sq10", 0.01);
  s.body("tip", 0.1, Vec3(1e-5, 1e-5, 1e-5), Vec3(1, 0, 0));
  s.beam("arm", "ground", "tip", Vec3::Zero(), Vec3(1, 0, 0), "steel", "sq10");
  s.last_beam()["segments"] = 8;
  s.force("tip", Vec3(0, -200, 0));
  const Model model = s.model();
  const int tip = body_index(model, "tip");
  Data by_load(model), by_arc(model);
  const StaticResult load = solve_static(model, StaticOptions{}, by_load);
  StaticOptions arc;
  arc.control = StaticControl::kArcLength;
  const StaticResult path = solve_static(model, arc, by_arc);
  ASSERT_TRUE(load.ok) << load.message;
  ASSERT_TRUE(path.ok) << path.message;
  const double difference = (by_arc.pose[tip].u - by_load.pose[tip].u).norm();
  std::printf(
      "cantilever, tip force: tip moved %.6f m; arc length vs load control %.2e m, %zu "
      "points, load factors rising: %s\n",
      by_load.pose[tip].u.norm(), difference, path.path.size(),
      std::is_sorted(path.path.begin(), path.path.end(),
                     [](const StaticPathPoint& a, const StaticPathPoint& b) {
                       return a.load_factor < b.load_factor;
                     })
          ? "yes"
          : "no");
  EXPECT_GT(by_load.pose[tip].u.norm(), 0.3);
  EXPECT_LT(difference, 1e-9);
  EXPECT_TRUE(std::isnan(path.limit_load_factor));
  for (size_t k = 1; k < path.path.size(); ++k)
    EXPECT_GT(path.path[k].load_factor, path.path[k - 1].load_factor);
  // Only the scene's own body is recorded, not the segments'.
  ASSERT_EQ(path.path_bodies.size(), 1u);
  EXPECT_EQ(path.path_bodies[0], tip);
}

TEST(StaticPath, AFreeMechanismIsRefusedWithTheReason) {
  // A carriage on a prismatic rail (no stiffness along it) pushed across the rail: load control
  // finds no equilibrium (the bent rail's slope pushes the carriage along it); arc-length control
  // has no path along a mechanism and says so at the start instead of following one.
  Scene s;
  s.material("steel", 2.1e11, 8.1e10);
  s.square("sq10", 0.01);
  s.body("carriage", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(0.5, 0, 0));
  s.rail("guide", "prismatic", "ground", "carriage", Vec3::Zero(), Vec3(0.5, 0, 0), "steel",
         "sq10");
  s.force("carriage", Vec3(0, -10, 0));
  const Model model = s.model();
  Data by_load(model), by_arc(model);
  const StaticResult load = solve_static(model, StaticOptions{}, by_load);
  StaticOptions arc;
  arc.control = StaticControl::kArcLength;
  const StaticResult path = solve_static(model, arc, by_arc);
  std::printf("carriage on a rail: load control: %s; arc length: %s\n", load.message.c_str(),
              path.message.c_str());
  EXPECT_FALSE(load.ok);
  EXPECT_FALSE(path.ok);
  EXPECT_TRUE(path.path.empty() && path.load_steps == 0);  // refused before any step
  EXPECT_NE(path.message.find("without stiffness"), std::string::npos) << path.message;
}

}  // namespace
}  // namespace beamrail
