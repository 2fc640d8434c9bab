// Third-order jets (core/model/jet3.hpp) against closed-form mixed derivatives and third
// differences.
#include "core/model/jet3.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace beamrail {
namespace {

// x seeded in the directions of `mask` (bits: 1 = e1, 2 = e2, 4 = e3).
Jet3 seed(double x, int mask) {
  Jet3 j(x);
  for (int bit : {1, 2, 4})
    if (mask & bit) j.c[bit] = 1.0;
  return j;
}

TEST(Jet3, ProductsAndAtan2CarryTheirThirdMixedDerivative) {
  const double x = 0.7, y = -1.3, z = 2.1;
  // x y z: every first, second and third mixed derivative.
  const Jet3 p = seed(x, 1) * seed(y, 2) * seed(z, 4);
  EXPECT_DOUBLE_EQ(p.c[0], x * y * z);
  EXPECT_DOUBLE_EQ(p.c[1], y * z);
  EXPECT_DOUBLE_EQ(p.c[6], x);
  EXPECT_DOUBLE_EQ(p.c[7], 1.0);
  // atan2(y, x) z / x: d3/dx dy dz = d2/dx dy (atan2(y, x) / x).
  const double r2 = x * x + y * y;
  const double t = std::atan2(y, x), tx = -y / r2, ty = x / r2, txy = (y * y - x * x) / (r2 * r2);
  const Jet3 q = atan2(seed(y, 2), seed(x, 1)) * seed(z, 4) / seed(x, 1);
  // d2/dxdy (t / x) = txy / x - ty / x^2.
  EXPECT_NEAR(q.c[7], txy / x - ty / (x * x), 1e-14);
  EXPECT_NEAR(q.c[5], tx / x - t / (x * x), 1e-14);  // d2/dx dz
  EXPECT_NEAR(q.c[0], t * z / x, 1e-15);
}

TEST(Jet3, OneVariableSeededThriceGivesTheThirdDerivative) {
  const auto f = [](auto v) { return sqrt(v) * sin(v) / (1.0 + v * v); };
  const auto value = [](double v) { return std::sqrt(v) * std::sin(v) / (1.0 + v * v); };
  const double x = 1.7, h = 1e-3;
  const Jet3 j = f(seed(x, 7));
  // Third central difference: error ~ h^2 f^(5) / 4.
  const double third =
      (value(x + 2 * h) - 2 * value(x + h) + 2 * value(x - h) - value(x - 2 * h)) / (2 * h * h * h);
  const double second = (value(x + h) - 2 * value(x) + value(x - h)) / (h * h);
  std::printf("f''(1.7): jet %.12f, difference %.12f; f''': jet %.12f, difference %.12f\n", j.c[3],
              second, j.c[7], third);
  EXPECT_NEAR(j.c[3], second, 1e-6);
  EXPECT_NEAR(j.c[5], j.c[3], 0.0);
  EXPECT_NEAR(j.c[7], third, 1e-5);
  // atan2 of a point turning with its angle is the angle: every higher derivative vanishes.
  const Jet3 angle = seed(0.4, 7);
  const Jet3 back = atan2(2.0 * sin(angle), 2.0 * cos(angle));
  EXPECT_NEAR(back.c[0], 0.4, 1e-16);
  EXPECT_NEAR(back.c[1], 1.0, 1e-15);
  EXPECT_NEAR(back.c[3], 0.0, 1e-15);
  EXPECT_NEAR(back.c[7], 0.0, 1e-14);
}

}  // namespace
}  // namespace beamrail
