// Hyper-dual numbers (core/model/hyper_dual.hpp) against closed-form first and mixed second
// derivatives, and a composite function against second differences.
#include "core/model/hyper_dual.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace beamrail {
namespace {

using H = HyperDual;

// x seeded in e1, y in e2.
H seed_x(double x) { return {x, 1.0, 0.0, 0.0}; }
H seed_y(double y) { return {y, 0.0, 1.0, 0.0}; }

TEST(HyperDual, ProductsQuotientsAndAtan2CarryTheirMixedDerivatives) {
  const double x = 0.7, y = -1.3;
  // x y: d/dx = y, d/dy = x, d2/dxdy = 1.
  const H p = seed_x(x) * seed_y(y);
  EXPECT_DOUBLE_EQ(p.v, x * y);
  EXPECT_DOUBLE_EQ(p.a, y);
  EXPECT_DOUBLE_EQ(p.b, x);
  EXPECT_DOUBLE_EQ(p.ab, 1.0);
  // x / y: 1/y, -x/y^2, -1/y^2.
  const H q = seed_x(x) / seed_y(y);
  EXPECT_NEAR(q.a, 1.0 / y, 1e-15);
  EXPECT_NEAR(q.b, -x / (y * y), 1e-15);
  EXPECT_NEAR(q.ab, -1.0 / (y * y), 1e-15);
  // atan2(y, x): d/dx = -y/r^2, d/dy = x/r^2, d2/dxdy = (y^2 - x^2)/r^4.
  const double r2 = x * x + y * y;
  const H t = atan2(seed_y(y), seed_x(x));
  EXPECT_DOUBLE_EQ(t.v, std::atan2(y, x));
  EXPECT_NEAR(t.a, -y / r2, 1e-15);
  EXPECT_NEAR(t.b, x / r2, 1e-15);
  EXPECT_NEAR(t.ab, (y * y - x * x) / (r2 * r2), 1e-15);
}

TEST(HyperDual, OneVariableSeededTwiceGivesTheSecondDerivative) {
  // f(x) = sqrt(x) sin(x) / (1 + x^2): f'' by hand.
  const double x = 1.7;
  const H hx{x, 1.0, 1.0, 0.0};
  const H f = sqrt(hx) * sin(hx) / (1.0 + hx * hx);
  const auto value = [](double z) { return std::sqrt(z) * std::sin(z) / (1.0 + z * z); };
  // g = sqrt(x) sin(x), h = 1 / (1 + x^2).
  const double g = std::sqrt(x) * std::sin(x);
  const double g1 = 0.5 / std::sqrt(x) * std::sin(x) + std::sqrt(x) * std::cos(x);
  const double g2 = -0.25 * std::pow(x, -1.5) * std::sin(x) + std::cos(x) / std::sqrt(x) -
                    std::sqrt(x) * std::sin(x);
  const double d = 1.0 + x * x;
  const double h = 1.0 / d, h1 = -2.0 * x / (d * d), h2 = (6.0 * x * x - 2.0) / (d * d * d);
  EXPECT_NEAR(f.v, value(x), 1e-15);
  EXPECT_NEAR(f.a, g1 * h + g * h1, 1e-14);
  EXPECT_NEAR(f.b, f.a, 0.0);
  EXPECT_NEAR(f.ab, g2 * h + 2.0 * g1 * h1 + g * h2, 1e-14);
  // And a second difference agrees to its truncation (~1e-8 here).
  const double s = 1e-4;
  const double second = (value(x + s) - 2.0 * value(x) + value(x - s)) / (s * s);
  std::printf("f''(1.7): hyper-dual %.15f, second difference %.15f\n", f.ab, second);
  EXPECT_NEAR(f.ab, second, 1e-6);
}

}  // namespace
}  // namespace beamrail
