#include "core/model/rotation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "tests/support/random_elements.hpp"

namespace beamrail {
namespace {

TEST(Rotation, MatrixIsProperOrthogonalAndMatchesQuaternionProduct) {
  testing::Random rng(1);
  for (int i = 0; i < 100; ++i) {
    const Vec4 q =
        Vec4(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    const Mat3 a = rotation_matrix<double>(q);
    EXPECT_LT((a * a.transpose() - Mat3::Identity()).norm(), 1e-14);
    EXPECT_NEAR(a.determinant(), 1.0, 1e-14);
    // A v equals the vector part of q (x) (0, v) (x) q* for unit q.
    const Vec4 qn = q.normalized();
    const Vec3 v = rng.vec3(1.0);
    Vec4 pv(0, v(0), v(1), v(2)), qc(qn(0), -qn(1), -qn(2), -qn(3));
    const Vec4 r = quat_multiply(quat_multiply(qn, pv), qc);
    EXPECT_LT((a * v - r.tail<3>()).norm(), 1e-14);
  }
}

TEST(Rotation, RoundTripsThroughMatrixAndRotationVector) {
  testing::Random rng(2);
  for (int i = 0; i < 100; ++i) {
    const Mat3 a = rng.rotation();
    EXPECT_LT((rotation_matrix<double>(quat_from_rotation_matrix(a)) - a).norm(), 1e-13);
    const Vec3 theta = rng.vec3(3.0 / std::sqrt(3.0));
    const Mat3 b = rotation_matrix<double>(quat_from_rotation_vector(theta));
    EXPECT_LT((rotation_vector(b) - theta).norm(), 1e-12);
    EXPECT_LT((b * theta - theta).norm(), 1e-12);  // the axis is fixed
  }
}

// The angle between a and a (x) exp(theta) is |theta| whatever the signs and norms of the Euler
// parameters, to rounding also at a nanoradian (where 2 acos(r0) would lose every digit).
TEST(Rotation, AngleBetweenOrientationsIsTheRelativeTurn) {
  testing::Random rng(3);
  for (double size : {1e-9, 1e-4, 0.5, 3.0}) {
    for (int i = 0; i < 20; ++i) {
      const Vec4 a = quat_from_rotation_matrix(rng.rotation());
      Vec3 theta = rng.vec3(1.0);
      theta *= size / theta.norm();
      const Vec4 b = quat_multiply(a, quat_from_rotation_vector(theta));
      EXPECT_NEAR(rotation_angle_between(a, b), size, 1e-15 + 4e-15 * size);
      EXPECT_NEAR(rotation_angle_between(-2.0 * a, 0.5 * b), size, 1e-15 + 4e-15 * size);
      EXPECT_NEAR(rotation_angle_between(b, a), size, 1e-15 + 4e-15 * size);
    }
  }
}

TEST(Rotation, IncrementJacobianMatchesFiniteDifferences) {
  testing::Random rng(3);
  for (int i = 0; i < 50; ++i) {
    Vec4 q(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    q *= rng.uniform(0.5, 2.0);  // not normalized on purpose
    const Mat3 a = rotation_matrix<double>(q);
    const Mat34 jac = rotation_increment_jacobian(q);
    const double h = 1e-7;
    for (int k = 0; k < 4; ++k) {
      Vec4 qp = q, qm = q;
      qp(k) += h, qm(k) -= h;
      // exp([theta]x) = A(q + dq) A(q)^T to first order: theta from the skew part.
      const Mat3 d =
          (rotation_matrix<double>(qp) - rotation_matrix<double>(qm)) / (2 * h) * a.transpose();
      const Vec3 theta(d(2, 1), d(0, 2), d(1, 0));
      EXPECT_LT((theta - jac.col(k)).norm(), 1e-7 * (1.0 + jac.col(k).norm()));
    }
  }
}

TEST(Rotation, RotationVectorRateMatchesFiniteDifferences) {
  // A(t) = exp([omega]x t) exp([theta]x): d/dt log(A) at t = 0 against central differences, over
  // angles from the series branch (1e-3 rad) to 2.8 rad.
  testing::Random rng(5);
  double worst = 0.0;
  for (double angle : {1e-3, 0.01, 0.3, 1.0, 2.0, 2.8}) {
    for (int i = 0; i < 20; ++i) {
      const Vec3 theta = angle * rng.vec3(1.0).normalized();
      const Vec3 omega = rng.vec3(1.0);
      const Mat3 a0 = rotation_matrix<double>(quat_from_rotation_vector(theta));
      const double h = 1e-6;
      const auto at = [&](double t) {
        return rotation_vector(rotation_matrix<double>(quat_from_rotation_vector(omega * t)) * a0);
      };
      const Vec3 fd = (at(h) - at(-h)) / (2 * h);
      const Vec3 rate = rotation_vector_rate(theta, omega);
      worst = std::max(worst, (rate - fd).norm() / omega.norm());
      EXPECT_LT((rate - fd).norm(), 1e-8 * omega.norm()) << "angle " << angle;
    }
  }
  std::printf("rotation_vector_rate vs finite differences: worst relative difference %.2e\n",
              worst);
  // Near zero it is omega - theta x omega / 2 to first order.
  const Vec3 small(1e-9, -2e-9, 3e-9), omega(0.3, -0.1, 0.7);
  EXPECT_LT((rotation_vector_rate(small, omega) - (omega - 0.5 * small.cross(omega))).norm(),
            1e-17);
}

TEST(Rotation, AngularVelocityInvertsTheRotationVectorRate) {
  // theta(t) = theta0 + v t: [omega]x = dA/dt A^T by central differences, and the round trip
  // through rotation_vector_rate, from the series branch to 2.8 rad.
  testing::Random rng(6);
  double worst_fd = 0.0, worst_trip = 0.0;
  for (double angle : {1e-3, 0.05, 0.1, 0.3, 1.0, 2.0, 2.8}) {
    for (int i = 0; i < 20; ++i) {
      const Vec3 theta = angle * rng.vec3(1.0).normalized(), v = rng.vec3(1.0);
      const double h = 1e-6;
      const auto at = [&](double t) {
        return rotation_matrix<double>(quat_from_rotation_vector(theta + v * t));
      };
      const Mat3 w = (at(h) - at(-h)) / (2 * h) * at(0).transpose();
      const Vec3 omega = angular_velocity(theta, v);
      const double fd = (Vec3(w(2, 1), w(0, 2), w(1, 0)) - omega).norm() / v.norm();
      const double trip = (rotation_vector_rate(theta, omega) - v).norm() / v.norm();
      worst_fd = std::max(worst_fd, fd);
      worst_trip = std::max(worst_trip, trip);
      EXPECT_LT(fd, 1e-8) << "angle " << angle;
      EXPECT_LT(trip, 1e-14) << "angle " << angle;
    }
  }
  std::printf("angular_velocity: vs finite differences %.2e, round trip %.2e (relative)\n",
              worst_fd, worst_trip);
}

TEST(Rotation, InverseJacobianCoefficientDerivativeMatchesDifferences) {
  // dc/ds against central differences of c, across the switch from the series at s = 1/4; c
  // continuous there.
  double worst = 0.0;
  for (double s : {1e-8, 1e-3, 0.1, 0.2499, 0.2501, 0.5, 2.0, 6.0}) {
    double c, d, cp, cm, unused;
    rotation_detail::inverse_jacobian_coefficient(s, &c, &d);
    const double h = 1e-4 * std::max(s, 1e-2);
    rotation_detail::inverse_jacobian_coefficient(s + h, &cp, &unused);
    rotation_detail::inverse_jacobian_coefficient(s - h, &cm, &unused);
    worst = std::max(worst, std::abs((cp - cm) / (2 * h) - d) / d);
    EXPECT_NEAR((cp - cm) / (2 * h), d, 1e-7 * d) << "s " << s;
  }
  double below, above, d_below, d_above;
  rotation_detail::inverse_jacobian_coefficient(std::nextafter(0.25, 0.0), &below, &d_below);
  rotation_detail::inverse_jacobian_coefficient(0.25, &above, &d_above);
  EXPECT_NEAR(below, above, 1e-15);
  EXPECT_NEAR(d_below, d_above, 1e-12 * d_above);
  std::printf(
      "dc/ds vs differences: worst relative %.2e; at the switch c %.17g / %.17g, dc/ds %.17g / "
      "%.17g\n",
      worst, below, above, d_below, d_above);
}

TEST(Rotation, RotationVectorAccelerationMatchesDifferences) {
  // theta(t) = theta0 + v t + alpha t^2 / 2: domega/dt of omega(t) = J(theta) dtheta/dt by central
  // differences; rotation_vector_acceleration must give alpha back.
  testing::Random rng(7);
  double worst = 0.0;
  for (double angle : {0.0, 1e-3, 0.1, 0.45, 0.55, 1.0, 2.5}) {
    for (int i = 0; i < 20; ++i) {
      const Vec3 theta = angle * rng.vec3(1.0).normalized(), v = rng.vec3(1.0),
                 alpha = rng.vec3(1.0);
      const auto omega = [&](double t) {
        return angular_velocity(theta + v * t + 0.5 * alpha * t * t, v + alpha * t);
      };
      const double h = 1e-4;
      const Vec3 omega_rate = (omega(h) - omega(-h)) / (2 * h);
      const double e =
          (rotation_vector_acceleration(theta, v, omega_rate) - alpha).norm() / alpha.norm();
      worst = std::max(worst, e);
      EXPECT_LT(e, 1e-7) << "angle " << angle;
    }
  }
  std::printf("rotation_vector_acceleration vs differences: worst relative %.2e\n", worst);
}

TEST(Rotation, QuaternionProductMatrices) {
  testing::Random rng(4);
  const Vec4 q(0.3, -0.5, 0.7, 0.1);
  const Vec3 w = rng.vec3(2.0);
  const Vec4 direct = quat_multiply(q, Vec4(0, w(0), w(1), w(2)));
  EXPECT_LT((quat_left_product_matrix(q) * w - direct).norm(), 1e-15);
  EXPECT_LT((quat_right_product_matrix(w) * q - direct).norm(), 1e-15);
}

}  // namespace
}  // namespace beamrail
