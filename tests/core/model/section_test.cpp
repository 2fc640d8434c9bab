// Section formulas (core/model/section.hpp) against textbook values. Width runs along local y,
// height along z: Iy = integral z^2 dA, Iz = integral y^2 dA, Wy = Iy / (height / 2),
// Wz = Iz / (width / 2).
#include "core/model/section.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

namespace beamrail {
namespace {

constexpr double kPi = std::numbers::pi;

double relative(double value, double expected) {
  return std::abs(value - expected) / std::abs(expected);
}

TEST(Section, RectangleAreaSecondMomentsAndModuliAreExact) {
  // width b = 0.03 (y), height h = 0.05 (z):
  //   S  = b h         = 0.03 * 0.05                 = 1.5e-3
  //   Iy = b h^3 / 12  = 0.03 * 1.25e-4 / 12         = 3.125e-7
  //   Iz = h b^3 / 12  = 0.05 * 2.7e-5 / 12          = 1.125e-7
  //   Wy = Iy / (h/2)  = b h^2 / 6 = 0.03 * 2.5e-3 / 6 = 1.25e-5
  //   Wz = Iz / (b/2)  = h b^2 / 6 = 0.05 * 9e-4 / 6   = 7.5e-6
  const SectionProperties s = rectangle_section(0.03, 0.05);
  EXPECT_LT(relative(s.area, 1.5e-3), 1e-14);
  EXPECT_LT(relative(s.iy, 3.125e-7), 1e-14);
  EXPECT_LT(relative(s.iz, 1.125e-7), 1e-14);
  EXPECT_LT(relative(s.wy, 1.25e-5), 1e-14);
  EXPECT_LT(relative(s.wz, 7.5e-6), 1e-14);
  EXPECT_EQ(s.torsion_constant, rectangle_torsion_constant(0.03, 0.05));
  std::printf(
      "rectangle 0.03 x 0.05: S %.2e, Iy %.2e, Iz %.2e, Wy %.2e, Wz %.2e (relative errors)\n",
      relative(s.area, 1.5e-3), relative(s.iy, 3.125e-7), relative(s.iz, 1.125e-7),
      relative(s.wy, 1.25e-5), relative(s.wz, 7.5e-6));
}

// Saint-Venant: J = beta a b^3 (a >= b) with
//   beta = (1/3) [1 - (192 / pi^5) (b/a) sum_{n odd} tanh(n pi a / (2b)) / n^5].
// Timoshenko & Goodier, Theory of Elasticity, table of k1 for the rectangle (4 digits), and the
// same series summed to 16 digits with mpmath (30 digits working precision).
TEST(Section, RectangleTorsionConstantMatchesTheClassicalTable) {
  struct Row {
    double ratio, table, series;
  };
  const Row rows[] = {{1.0, 0.1406, 0.1405770149551537}, {1.5, 0.1958, 0.1957607088755440},
                      {2.0, 0.2287, 0.2286816771195708}, {3.0, 0.2633, 0.2633169310015001},
                      {4.0, 0.2808, 0.2808129583076774}, {6.0, 0.2983, 0.2983195073271137},
                      {10.0, 0.3123, 0.3123250374572054}};
  const double b = 0.02;
  double worst_table = 0, worst_series = 0;
  for (const Row& row : rows) {
    const double a = row.ratio * b;
    const double beta = rectangle_torsion_constant(a, b) / (a * b * b * b);
    EXPECT_LE(std::abs(beta - row.table), 5e-5) << "a/b = " << row.ratio << ": beta = " << beta;
    // A converged series: 9 digits (docs/model.md "Validation"'s standard for linear cases).
    EXPECT_LT(relative(beta, row.series), 1e-9) << "a/b = " << row.ratio;
    worst_table = std::max(worst_table, std::abs(beta - row.table));
    worst_series = std::max(worst_series, relative(beta, row.series));
    // Either argument order; and rectangle_section agrees in both orientations.
    EXPECT_EQ(rectangle_torsion_constant(b, a), rectangle_torsion_constant(a, b));
    const SectionProperties wide = rectangle_section(a, b), tall = rectangle_section(b, a);
    EXPECT_EQ(wide.torsion_constant, tall.torsion_constant);
    EXPECT_EQ(wide.iy, tall.iz);
    EXPECT_EQ(wide.iz, tall.iy);
    EXPECT_EQ(wide.wy, tall.wz);
    EXPECT_EQ(wide.wz, tall.wy);
  }
  std::printf(
      "torsion beta: worst |beta - table| = %.2e (table: 4 digits), worst relative to the "
      "16-digit series = %.2e\n",
      worst_table, worst_series);
}

// Thin strips, a/b -> infinity: tanh -> 1 and sum_{n odd} 1/n^5 = (31/32) zeta(5), so
//   beta -> (1/3) (1 - c b/a),  c = (192 / pi^5) (31/32) zeta(5) = 0.6302488762838669,
// i.e. 1/3 - 0.2101 b/a, with an exponentially small remainder (tanh(500 pi) = 1 in doubles).
TEST(Section, RectangleTorsionConstantTendsToTheThinStripLimit) {
  const double b = 0.001;
  const double a = 1000 * b;
  const double beta = rectangle_torsion_constant(a, b) / (a * b * b * b);
  const double textbook = (1.0 - 0.630 * b / a) / 3.0;  // the usual 3-digit coefficient
  const double exact = (1.0 - 0.6302488762838669 * b / a) / 3.0;
  std::printf(
      "a/b = 1000: beta = %.12f, |beta - (1 - 0.630 b/a)/3| = %.2e, relative to the exact "
      "asymptote %.2e\n",
      beta, std::abs(beta - textbook), relative(beta, exact));
  EXPECT_LE(std::abs(beta - textbook), 1e-4);
  EXPECT_LT(relative(beta, exact), 1e-12);
  // Further out, beta tends to 1/3 like 0.21 b/a.
  const double beta6 = rectangle_torsion_constant(1e6 * b, b) / (1e6 * b * b * b * b);
  EXPECT_NEAR(beta6, 1.0 / 3.0 - 0.2100829587612890e-6, 1e-12);
}

TEST(Section, CircleIsExact) {
  // d = 0.04: S = pi d^2 / 4 = pi 4e-4; Iy = Iz = pi d^4 / 64 = pi 2.56e-6 / 64 = pi 4e-8;
  // J = pi d^4 / 32 = pi 8e-8; W = I / (d/2) = pi d^3 / 32 = pi 6.4e-5 / 32 = pi 2e-6.
  const SectionProperties s = circle_section(0.04);
  EXPECT_LT(relative(s.area, kPi * 4e-4), 1e-14);
  EXPECT_LT(relative(s.iy, kPi * 4e-8), 1e-14);
  EXPECT_LT(relative(s.iz, kPi * 4e-8), 1e-14);
  EXPECT_LT(relative(s.torsion_constant, kPi * 8e-8), 1e-14);
  EXPECT_LT(relative(s.wy, kPi * 2e-6), 1e-14);
  EXPECT_LT(relative(s.wz, kPi * 2e-6), 1e-14);
}

TEST(Section, TubeIsExact) {
  // D = 0.05, t = 0.004, inner d = D - 2t = 0.042:
  //   S = pi (D^2 - d^2) / 4 = pi t (D - t) = pi 0.004 * 0.046          = pi 1.84e-4
  //   D^4 = 6.25e-6, d^4 = 3.111696e-6, D^4 - d^4 = 3.138304e-6
  //   Iy = Iz = pi (D^4 - d^4) / 64 = pi 4.9036e-8;  J = pi (D^4 - d^4) / 32 = pi 9.8072e-8
  //   W = I / (D/2) = pi 4.9036e-8 / 0.025 = pi 1.96144e-6
  const SectionProperties s = tube_section(0.05, 0.004);
  EXPECT_LT(relative(s.area, kPi * 1.84e-4), 1e-14);
  EXPECT_LT(relative(s.iy, kPi * 4.9036e-8), 1e-14);
  EXPECT_LT(relative(s.iz, kPi * 4.9036e-8), 1e-14);
  EXPECT_LT(relative(s.torsion_constant, kPi * 9.8072e-8), 1e-14);
  EXPECT_LT(relative(s.wy, kPi * 1.96144e-6), 1e-14);
  EXPECT_LT(relative(s.wz, kPi * 1.96144e-6), 1e-14);
}

// Wall -> D/2: the bore d = 1e-7 D changes S by (d/D)^2 = 1e-14 and I, J by (d/D)^4 relative.
TEST(Section, TubeWithWallTendingToTheRadiusIsTheSolidCircle) {
  const double d = 0.05;
  const SectionProperties tube = tube_section(d, 0.5 * d * (1.0 - 1e-7));
  const SectionProperties solid = circle_section(d);
  EXPECT_LT(relative(tube.area, solid.area), 1e-12);
  EXPECT_LT(relative(tube.iy, solid.iy), 1e-12);
  EXPECT_LT(relative(tube.iz, solid.iz), 1e-12);
  EXPECT_LT(relative(tube.torsion_constant, solid.torsion_constant), 1e-12);
  EXPECT_LT(relative(tube.wy, solid.wy), 1e-12);
  EXPECT_LT(relative(tube.wz, solid.wz), 1e-12);
}

// Thin tube of mean radius r and wall t: D = 2r + t, d = 2r - t, D^4 - d^4 = (D^2 - d^2)(D^2 + d^2)
// = 8 r t (8 r^2 + 2 t^2), so J = pi (D^4 - d^4) / 32 = 2 pi r^3 t (1 + (t/r)^2 / 4): the thin-wall
// value 2 pi r^3 t with a relative difference O(t/r) (here even (t/r)^2 / 4, exactly).
TEST(Section, ThinTubeTorsionConstantIsTwoPiRCubedT) {
  const double r = 0.05;
  double previous = 1.0;
  for (double ratio : {0.1, 0.03, 0.01, 0.003}) {
    const double t = ratio * r;
    const SectionProperties s = tube_section(2 * r + t, t);
    const double difference = s.torsion_constant / (2 * kPi * r * r * r * t) - 1.0;
    std::printf("thin tube t/r = %.3f: J / (2 pi r^3 t) - 1 = %.3e (exact: (t/r)^2/4 = %.3e)\n",
                ratio, difference, ratio * ratio / 4);
    EXPECT_LE(std::abs(difference), ratio);
    EXPECT_LT(std::abs(difference - ratio * ratio / 4), 1e-12);
    EXPECT_LT(std::abs(difference), previous);
    previous = std::abs(difference);
  }
}

// Box W x H with wall t: second moments by parallel axes over two flanges (W x t, centroids at
// +-(H - t)/2) and two webs (t x (H - 2t), centroids at +-(W - t)/2), independent of the kernel's
// outer-minus-inner subtraction. W = 0.1, H = 0.2, t = 0.01:
//   S  = 2 W t + 2 t (H - 2t) = 2e-3 + 3.6e-3                          = 5.6e-3
//   Iy = 2 [W t^3/12 + W t ((H-t)/2)^2] + 2 t (H-2t)^3/12
//      = 1.806667e-5 + 9.72e-6 = 2.778667e-5 (= (0.1*0.2^3 - 0.08*0.18^3)/12 = 3.3344e-4/12)
//   Iz = 2 t W^3/12 + 2 [(H-2t) t^3/12 + (H-2t) t ((W-t)/2)^2]
//      = 1.666667e-6 + 7.32e-6 = 8.986667e-6 (= (0.2*0.1^3 - 0.18*0.08^3)/12 = 1.0784e-4/12)
TEST(Section, BoxSecondMomentsAreExact) {
  const double w = 0.1, h = 0.2, t = 0.01;
  const SectionProperties s = box_section(w, h, t);
  const double web = h - 2 * t;
  const double area = 2 * w * t + 2 * t * web;
  const double iy =
      2 * (w * t * t * t / 12 + w * t * std::pow((h - t) / 2, 2)) + 2 * t * web * web * web / 12;
  const double iz =
      2 * t * w * w * w / 12 + 2 * (web * t * t * t / 12 + web * t * std::pow((w - t) / 2, 2));
  std::printf("box 0.1 x 0.2 x 0.01: S %.2e, Iy %.2e, Iz %.2e (relative to parallel axes)\n",
              relative(s.area, area), relative(s.iy, iy), relative(s.iz, iz));
  EXPECT_LT(relative(s.area, 5.6e-3), 1e-14);
  EXPECT_LT(relative(s.area, area), 1e-14);
  EXPECT_LT(relative(s.iy, iy), 1e-14);
  EXPECT_LT(relative(s.iz, iz), 1e-14);
  EXPECT_LT(relative(s.iy, 3.3344e-4 / 12), 1e-14);
  EXPECT_LT(relative(s.iz, 1.0784e-4 / 12), 1e-14);
  EXPECT_LT(relative(s.wy, s.iy / (h / 2)), 1e-14);
  EXPECT_LT(relative(s.wz, s.iz / (w / 2)), 1e-14);
}

// Bredt, thin closed section of uniform wall t: J = 4 Am^2 t / pm (Am: area inside the median
// line, pm: its length). Square box b = 0.1, t = 0.005: median side 0.095, Am = 0.009025,
// pm = 0.38, J = 4 * 8.1450625e-5 * 0.005 / 0.38 = 4.286875e-6 (= (b - t)^3 t).
// Rectangular box 0.1 x 0.2, t = 0.01: Am = 0.09 * 0.19 = 0.0171, pm = 2 (0.09 + 0.19) = 0.56,
// J = 4 * 2.9241e-4 * 0.01 / 0.56 = 1.16964e-5 / 0.56.
TEST(Section, BoxTorsionConstantIsBredts) {
  EXPECT_LT(relative(box_section(0.1, 0.1, 0.005).torsion_constant, 4.286875e-6), 1e-14);
  EXPECT_LT(relative(box_section(0.1, 0.2, 0.01).torsion_constant, 1.16964e-5 / 0.56), 1e-14);
}

// As the wall thins at fixed median dimensions Wm, Hm, Iy tends to the thin-wall value
// t Hm^2 (Wm/2 + Hm/6) (flanges Wm t at +-Hm/2, webs t Hm^3/12). Expanding the exact
// (W H^3 - (W - 2t)(H - 2t)^3)/12 with W = Wm + t, H = Hm + t leaves exactly t^3 (Hm/2 + Wm/6):
// the relative difference e(t) = t^2 k / (A + t^2 k), k = Hm/2 + Wm/6, A = Hm^2 (Wm/2 + Hm/6), is
// second order in t: e(2t) / e(t) = 4 (A + t^2 k) / (A + 4 t^2 k) -> 4.
TEST(Section, BoxSecondMomentConvergesToTheThinWallValue) {
  const double wm = 0.1, hm = 0.2;
  const double k = hm / 2 + wm / 6, a = hm * hm * (wm / 2 + hm / 6);
  double previous = 0;
  for (double t : {0.01, 0.005, 0.0025, 0.00125}) {
    const SectionProperties s = box_section(wm + t, hm + t, t);
    const double thin = t * a;
    const double difference = (s.iy - thin) / s.iy;
    EXPECT_LT(relative(s.iy - thin, t * t * t * k), 1e-8) << "t = " << t;
    if (previous > 0) {
      const double ratio = previous / difference;
      const double predicted = 4 * (a + t * t * k) / (a + 4 * t * t * k);
      std::printf(
          "box Iy vs thin wall: t = %.5f: relative difference %.3e, e(2t)/e(t) = %.6f "
          "(predicted %.6f)\n",
          t, difference, ratio, predicted);
      EXPECT_LT(std::abs(ratio - predicted), 1e-6) << "t = " << t;
      EXPECT_LT(std::abs(ratio - 4.0), 50 * t * t * k / a) << "t = " << t;  // -> 4 like t^2
    }
    previous = difference;
  }
}

}  // namespace
}  // namespace beamrail
