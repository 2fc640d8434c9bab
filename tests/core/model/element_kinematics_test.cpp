// The rotation vector measure of core/model/element_kinematics.hpp: phi against an independent
// logarithm (rotation_vector, through Euler parameters), T against central differences of that
// logarithm and against the inverse of the left Jacobian of exp in its closed form, and the
// derivatives that forward AD takes through it (the tangent's dT) against central differences of T,
// on both sides of its series branches and exactly at the identity.
#include "core/model/element_kinematics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/model/dual.hpp"
#include "core/model/rotation.hpp"
#include "tests/support/random_elements.hpp"

namespace beamrail {
namespace {

using testing::Random;

Mat3 exp_rotation(const Vec3& theta) {
  return rotation_matrix<double>(quat_from_rotation_vector(theta));
}

struct Measured {
  Vec3 phi;
  Mat3 t;
};

Measured measure(const Mat3& a) {
  Measured m;
  relative_rotation_vector(a, m.phi, m.t);
  return m;
}

// Angles across the series thresholds (sin^2 = 1e-4, theta^2 = 1e-2) and up to the range limit.
const double kAngles[] = {1e-12, 1e-7, 1e-3, 0.0099, 0.0101, 0.0999, 0.1001, 0.5, 1.5, 2.5, 3.0};

TEST(ElementKinematics, RotationVectorIsTheLogarithm) {
  Random rng(70);
  double worst = 0;
  for (double angle : kAngles)
    for (int i = 0; i < 20; ++i) {
      const Vec3 phi = angle * rng.vec3(1.0).normalized();
      const Mat3 a = exp_rotation(phi);
      const Vec3 independent = rotation_vector(a);
      worst = std::max(worst, (measure(a).phi - independent).norm() / angle);
      EXPECT_NEAR(independent.norm(), angle, 1e-15 + 1e-13 * angle);
    }
  std::printf("rotation vector vs rotation_vector(a): worst relative difference %.2e\n", worst);
  EXPECT_LT(worst, 1e-13);
}

// T = d log(exp([delta]x) a) / d delta, by central differences of the independent logarithm.
TEST(ElementKinematics, DerivativeEqualsCentralDifferencesOfTheLogarithm) {
  Random rng(71);
  for (double angle : kAngles) {
    double worst = 0;
    for (int i = 0; i < 20; ++i) {
      const Mat3 a = exp_rotation(angle * rng.vec3(1.0).normalized());
      const Mat3 t = measure(a).t;
      const double h = 1e-6;
      Mat3 fd;
      for (int k = 0; k < 3; ++k) {
        const Vec3 step = h * Vec3::Unit(k);
        fd.col(k) =
            (rotation_vector(exp_rotation(step) * a) - rotation_vector(exp_rotation(-step) * a)) /
            (2 * h);
      }
      worst = std::max(worst, (t - fd).cwiseAbs().maxCoeff());
    }
    std::printf("theta = %-7.3g T vs central differences of log: worst %.2e\n", angle, worst);
    EXPECT_LT(worst, 1e-8) << angle;
  }
}

// T J_l(phi) = I with the left Jacobian J_l = I + (1 - cos)/theta^2 [phi]x + (theta - sin)/theta^3
// [phi]x^2 (exp([phi + J_l^-1 delta]x) = exp([delta]x) exp([phi]x)).
TEST(ElementKinematics, DerivativeIsTheInverseLeftJacobian) {
  Random rng(72);
  double worst = 0;
  for (double angle : {0.1, 0.5, 1.0, 2.0, 2.5, 3.0})
    for (int i = 0; i < 20; ++i) {
      const Vec3 phi = angle * rng.vec3(1.0).normalized();
      const Mat3 p = skew<double>(phi);
      const Mat3 jl = Mat3::Identity() + (1 - std::cos(angle)) / (angle * angle) * p +
                      (angle - std::sin(angle)) / (angle * angle * angle) * p * p;
      worst = std::max(worst, (measure(exp_rotation(phi)).t * jl - Mat3::Identity()).norm());
    }
  std::printf("T J_l - I: worst %.2e\n", worst);
  EXPECT_LT(worst, 1e-13);
}

// What configuration_jacobian differentiates: T along a' = a + [w]x a by forward AD, against
// central differences of T along exp([w]x) a; finite everywhere, and -1/2 [e_k]x at a = I.
TEST(ElementKinematics, ForwardDerivativesOfTAreExactIncludingAtTheIdentity) {
  Random rng(73);
  const auto ad_derivative = [](const Mat3& a, int k) {
    Vec3T<Dual<3>> w;
    for (int j = 0; j < 3; ++j) w(j) = Dual<3>(0.0, j);
    const Mat3T<Dual<3>> rotated = a.cast<Dual<3>>() + skew<Dual<3>>(w) * a;
    Vec3T<Dual<3>> phi;
    Mat3T<Dual<3>> t;
    relative_rotation_vector(rotated, phi, t);
    Mat3 d;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) d(r, c) = t(r, c).d[k];
    return d;
  };
  for (int k = 0; k < 3; ++k) {
    const Mat3 d = ad_derivative(Mat3::Identity(), k);
    EXPECT_TRUE(d.allFinite());
    EXPECT_LT((d + 0.5 * skew<double>(Vec3::Unit(k))).norm(), 1e-15) << k;
  }
  for (double angle : kAngles) {
    double worst = 0;
    for (int i = 0; i < 20; ++i) {
      const Mat3 a = exp_rotation(angle * rng.vec3(1.0).normalized());
      for (int k = 0; k < 3; ++k) {
        const double h = 1e-5;
        const Vec3 step = h * Vec3::Unit(k);
        const Mat3 fd =
            (measure(exp_rotation(step) * a).t - measure(exp_rotation(-step) * a).t) / (2 * h);
        worst = std::max(worst, (ad_derivative(a, k) - fd).cwiseAbs().maxCoeff());
      }
    }
    std::printf("theta = %-7.3g dT by AD vs central differences: worst %.2e\n", angle, worst);
    EXPECT_LT(worst, 1e-8) << angle;
  }
}

}  // namespace
}  // namespace beamrail
