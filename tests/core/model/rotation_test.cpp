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
