// Lee's frame under arc-length control (core/analysis/static_path.cpp): a right-angled frame of two
// 120-long members pinned at both ends, loaded 24 from its corner, whose path has a limit point
// (the load falls while the frame gives way), under a load of fixed direction and under a
// follower load that stays perpendicular to the beam. The reference is the planar extensible
// elastica of the same frame solved by shooting (an independent, continuous rod model): the
// segmented frame converges to its limit load at second order in the segments, and its path lies
// on the elastica's load-deflection curve.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "core/analysis/static_analysis.hpp"
#include "tests/support/scene_builder.hpp"

namespace beamrail {
namespace {

using testing::body_index;
using testing::Scene;
using testing::vec;

// The frame as published (Lee, Manuel and Rossow 1968; units consistent, any system): members of
// length L = 120, E = 720, A = 6, I = 2 (in the plane), the load 24 from the corner on the beam.
constexpr double kL = 120.0, kE = 720.0, kArea = 6.0, kI = 2.0, kLoadAt = 24.0;
constexpr double kEI = kE * kI, kEA = kE * kArea;

// --- The reference: the extensible elastica by shooting ---------------------------------------
//
// Arc length s runs from the foot A (0, 0) up the column to the corner (s = L, where the tangent
// turns by -90 degrees: a rigid corner) and along the beam to B (L, L) (s = 2L); the load acts at
// s_P = L + 24. With R the support force at A and P the load (vector), the part [0, s] exerts on
// the rest the force F(s) = R + [s > s_P] P and the moment M(s) = (A - p) x R + [s > s_P]
// (p_P - p) x P about p(s). Euler-Bernoulli, extensible:
//   p' = (1 + eps) (cos theta, sin theta),  theta' = -M / EI,  eps = -F . t / EA.
// The unknowns theta(0), R and P meet x_B = L, y_B = L, M(2L) = 0 (B pinned) and a given
// vertical displacement v of the load point (displacement control: it passes the limit load).
// A follower load is P (sin theta_P, -cos theta_P): perpendicular to the beam where it acts.
struct Elastica {
  bool follower = false;
  int steps = 2400;  // RK4 steps per member (the load point falls on a step)

  // Residuals (x_B - L, y_B - L, M_B / EI, v_P - v) of the unknowns u = (theta0, Rx, Ry, P).
  std::array<double, 4> residual(const std::array<double, 4>& u, double v) const {
    const double h = kL / steps;
    const double rx = u[1], ry = u[2], p = u[3];
    double x = 0.0, y = 0.0, th = u[0];
    double px = 0.0, py = 0.0, fx = 0.0, fy = 0.0;  // the load point and its force, once passed
    bool passed = false;
    const auto rhs = [&](double xs, double ys, double ts, double* d) {
      double m = (0.0 - xs) * ry - (0.0 - ys) * rx;
      double nx = rx, ny = ry;
      if (passed) {
        m += (px - xs) * fy - (py - ys) * fx;
        nx += fx, ny += fy;
      }
      const double c = std::cos(ts), s = std::sin(ts);
      const double eps = -(nx * c + ny * s) / kEA;
      d[0] = (1 + eps) * c, d[1] = (1 + eps) * s, d[2] = -m / kEI;
    };
    const int load_step =
        steps + steps * static_cast<int>(std::lround(kLoadAt)) / static_cast<int>(std::lround(kL));
    for (int k = 0; k < 2 * steps; ++k) {
      if (k == steps) th -= std::numbers::pi / 2;  // the corner
      if (k == load_step) {
        passed = true;
        px = x, py = y;
        fx = follower ? p * std::sin(th) : 0.0;
        fy = follower ? -p * std::cos(th) : -p;
      }
      double k1[3], k2[3], k3[3], k4[3];
      rhs(x, y, th, k1);
      rhs(x + 0.5 * h * k1[0], y + 0.5 * h * k1[1], th + 0.5 * h * k1[2], k2);
      rhs(x + 0.5 * h * k2[0], y + 0.5 * h * k2[1], th + 0.5 * h * k2[2], k3);
      rhs(x + h * k3[0], y + h * k3[1], th + h * k3[2], k4);
      x += h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]);
      y += h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]);
      th += h / 6 * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2]);
    }
    const double mb = (0.0 - x) * ry - (0.0 - y) * rx + (px - x) * fy - (py - y) * fx;
    return {x - kL, y - kL, mb / kEI, (py - kL) - v};
  }

  // Newton on u (finite-difference Jacobian) from the guess; true when converged.
  bool solve(double v, std::array<double, 4>& u) const {
    for (int it = 0; it < 40; ++it) {
      const std::array<double, 4> r = residual(u, v);
      double norm = 0.0;
      for (double x : r) norm = std::max(norm, std::abs(x));
      if (norm < 1e-11) return true;
      Eigen::Matrix4d j;
      for (int c = 0; c < 4; ++c) {
        std::array<double, 4> up = u;
        const double d = 1e-7 * std::max(1.0, std::abs(u[c]));
        up[c] += d;
        const std::array<double, 4> rp = residual(up, v);
        for (int k = 0; k < 4; ++k) j(k, c) = (rp[k] - r[k]) / d;
      }
      const Eigen::Vector4d step = j.fullPivLu().solve(Eigen::Vector4d(r[0], r[1], r[2], r[3]));
      for (int c = 0; c < 4; ++c) u[c] -= step(c);
    }
    return false;
  }

  // The load P at the vertical displacement v of the load point, continued from u (at v_u) in
  // steps of at most 2 in v.
  double load_at(double v, std::array<double, 4>& u, double* v_u = nullptr) const {
    double from = v_u ? *v_u : v;
    while (std::abs(v - from) > 2.0) {
      from += v > from ? 2.0 : -2.0;
      EXPECT_TRUE(solve(from, u)) << "the elastica did not converge at v = " << from;
    }
    EXPECT_TRUE(solve(v, u)) << "the elastica did not converge at v = " << v;
    if (v_u) *v_u = v;
    return u[3];
  }

  // The limit load: the largest P along v (sampled from 0 by dv, then golden section).
  double limit_load(double* v_limit) const {
    std::array<double, 4> u{std::numbers::pi / 2, 0.0, 0.0, 0.0};
    double v = 0.0, best = -1.0;
    const double dv = -2.0;
    std::array<double, 4> u_best = u;
    for (;;) {
      v += dv;
      const double p = load_at(v, u);
      if (p < best) break;
      best = p, u_best = u;
    }
    double lo = v, hi = v - 2 * dv;  // the maximum lies between
    const double g = (std::sqrt(5.0) - 1.0) / 2.0;
    for (int k = 0; k < 40; ++k) {
      const double m1 = hi - g * (hi - lo), m2 = lo + g * (hi - lo);
      std::array<double, 4> u1 = u_best, u2 = u_best;
      if (load_at(m1, u1) > load_at(m2, u2))
        hi = m2;
      else
        lo = m1;
    }
    *v_limit = 0.5 * (lo + hi);
    std::array<double, 4> w = u_best;
    return load_at(*v_limit, w);
  }
};

// --- The segmented frame ------------------------------------------------------------------

Json pin(const std::string& name, const std::string& body, const Vec3& p) {
  Json j = testing::joint(name, "revolute", "ground", body, p);
  j["axis"] = vec(0, 0, 1);
  return j;
}

// The frame in 10 k segments (column 5 k, beam 1 k + 4 k, so that the load point is a node),
// pinned at both ends by revolute joints about z, the load p at the load point. Out of its plane
// the section is 100 times stiffer in bending and torsion (the frame stays planar: with equal
// stiffnesses its column, compressed beyond its own out-of-plane Euler load, would buckle
// sideways).
Model lee_frame(int k, double p, bool follower) {
  Scene s;
  s.material("lee", kE, 0.4 * kE, 1.0);            // a density: segments need one (no gravity)
  s.custom("lee", kArea, 100 * kI, 100 * kI, kI);  // Iz about global z: in the plane
  const Vec3 inertia(1, 1, 1);
  const Vec3 a(0, 0, 0), corner(0, kL, 0), load(kLoadAt, kL, 0), b(kL, kL, 0);
  s.body("foot", 1.0, inertia, a).body("corner", 1.0, inertia, corner);
  s.body("load", 1.0, inertia, load).body("head", 1.0, inertia, b);
  const auto member = [&](const std::string& name, const std::string& b1, const std::string& b2,
                          const Vec3& p1, const Vec3& p2, const Vec3& side, int segments) {
    s.beam(name, b1, b2, p1, p2, "lee", "lee");
    const Vec3 p3 = p1 + side;  // local y in the plane
    s.last_beam()["point3"] = vec(p3(0), p3(1), p3(2));
    s.last_beam()["segments"] = segments;
  };
  member("column", "foot", "corner", a, corner, Vec3(-1, 0, 0), 5 * k);
  member("beam_a", "corner", "load", corner, load, Vec3(0, 1, 0), k);
  member("beam_b", "load", "head", load, b, Vec3(0, 1, 0), 4 * k);
  s.j["joints"] = Json::array({pin("pin_a", "foot", a), pin("pin_b", "head", b)});
  s.force("load", Vec3(0, -p, 0));
  s.j["loads"].back()["follows"] = follower;
  return s.model();
}

struct PathRun {
  StaticResult result;
  int column = -1;  // the load point's column in the path
};

PathRun run_path(int k, double p, bool follower) {
  const Model model = lee_frame(k, p, follower);
  StaticOptions options;
  options.control = StaticControl::kArcLength;
  options.max_load_steps = 2000;
  Data data(model);
  PathRun run;
  run.result = solve_static(model, options, data);
  const int load = body_index(model, "load");
  for (size_t c = 0; c < run.result.path_bodies.size(); ++c)
    if (run.result.path_bodies[c] == load) run.column = static_cast<int>(c);
  return run;
}

void check_lee_frame(bool follower) {
  const char* label = follower ? "follower load" : "load of fixed direction";
  Elastica elastica;
  elastica.follower = follower;
  double v_limit = 0.0;
  const double limit = elastica.limit_load(&v_limit);
  // The reference's own discretization: half the steps.
  Elastica coarse = elastica;
  coarse.steps /= 2;
  double v_coarse = 0.0;
  const double limit_coarse = coarse.limit_load(&v_coarse);
  std::printf(
      "Lee's frame, %s: elastica limit load %.8f EI/L^2 = %.8f at v = %.4f (with half the RK4 "
      "steps: %+.1e)\n",
      label, limit * kL * kL / kEI, limit, v_limit, limit_coarse - limit);
  ASSERT_LT(std::abs(limit_coarse - limit), 1e-7 * limit);

  const double p = 1.2 * limit;
  std::vector<double> errors, path_errors, limits;
  for (int k : {1, 2, 4, 8, 16}) {
    const PathRun run = run_path(k, p, follower);
    ASSERT_GE(run.column, 0);
    ASSERT_TRUE(run.result.ok) << label << ", " << 10 * k << " segments: " << run.result.message;
    limits.push_back(run.result.limit_load_factor * p);
    errors.push_back(std::abs(limits.back() / limit - 1));
    // The path's points up to the elastica's limit deflection (where the load rises with it)
    // against the elastica's load at their deflection.
    std::array<double, 4> u{std::numbers::pi / 2, 0.0, 0.0, 0.0};
    double worst = 0.0, v_u = 0.0;
    int compared = 0;
    for (const StaticPathPoint& point : run.result.path) {
      const double v = point.displacement[run.column](1);
      if (v < v_limit) break;
      worst =
          std::max(worst, std::abs(point.load_factor * p - elastica.load_at(v, u, &v_u)) / limit);
      ++compared;
    }
    path_errors.push_back(worst);
    const size_t n = errors.size();
    std::printf(
        "  %3d segments: %zu path points, limit load %.8f (error %.3e, order %.3f); %d points up "
        "to the limit deflection within %.2e P_limit of the elastica (order %.3f)\n",
        10 * k, run.result.path.size(), limits.back(), errors.back(),
        n > 1 ? std::log2(errors[n - 2] / errors[n - 1]) : NAN, compared, worst,
        n > 1 ? std::log2(path_errors[n - 2] / path_errors[n - 1]) : NAN);
    EXPECT_GT(compared, 10);
  }
  // Second order: the orders rise towards 2 (the follower load's slowly: 1.6, 1.86, 1.94) and
  // the finest pair's is 2; the extrapolation from it lands on the elastica.
  const size_t n = errors.size();
  EXPECT_NEAR(std::log2(errors[n - 2] / errors[n - 1]), 2.0, 0.1) << label;
  EXPECT_NEAR(std::log2(path_errors[n - 2] / path_errors[n - 1]), 2.0, 0.1) << label;
  EXPECT_GT(std::log2(errors[n - 2] / errors[n - 1]),
            std::log2(errors[n - 3] / errors[n - 2]) - 0.05)
      << label;
  const double extrapolated = (4 * limits[n - 1] - limits[n - 2]) / 3;
  std::printf("  extrapolated from 80 and 160 segments: %.8f (%+.1e)\n", extrapolated,
              extrapolated / limit - 1);
  EXPECT_NEAR(extrapolated, limit, 1e-4 * limit);
}

TEST(LeeFrame, DeadLoadLimitConvergesToTheElastica) { check_lee_frame(false); }
TEST(LeeFrame, FollowerLoadLimitConvergesToTheElastica) { check_lee_frame(true); }

}  // namespace
}  // namespace beamrail
