// Exact element tangents by forward-mode automatic differentiation (Eigen AutoDiff) through the
// element kernels: derivatives of the two bodies' wrenches with respect to the configuration
// increments (dc1, dtheta1, dc2, dtheta2) or the velocities (v1, omega1, v2, omega2).
#pragma once

#include <unsupported/Eigen/AutoDiff>

#include "core/model/element_kinematics.hpp"

namespace beamrail {

using Ad12 = Eigen::AutoDiffScalar<Eigen::Matrix<double, 12, 1>>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

// Pose whose centre and orientation carry derivative seeds offset..offset+5 (dc, dtheta):
// A(theta) = (I + [theta]x) A agrees with exp([theta]x) A to first order, which is all a first
// derivative at theta = 0 needs.
inline Pose<Ad12> seed_configuration(const Pose<double>& p, int offset) {
  Pose<Ad12> s;
  Vec3T<Ad12> theta;
  for (int j = 0; j < 3; ++j) {
    s.c(j) = Ad12(p.c(j), 12, offset + j);
    theta(j) = Ad12(0.0, 12, offset + 3 + j);
  }
  const Mat3T<Ad12> a = p.A.cast<Ad12>();
  s.A = a + skew<Ad12>(theta) * a;
  s.v = p.v.cast<Ad12>();
  s.omega = p.omega.cast<Ad12>();
  return s;
}

// Pose whose velocities carry derivative seeds offset..offset+5 (v, omega).
inline Pose<Ad12> seed_velocity(const Pose<double>& p, int offset) {
  Pose<Ad12> s;
  s.c = p.c.cast<Ad12>();
  s.A = p.A.cast<Ad12>();
  for (int j = 0; j < 3; ++j) {
    s.v(j) = Ad12(p.v(j), 12, offset + j);
    s.omega(j) = Ad12(p.omega(j), 12, offset + 3 + j);
  }
  return s;
}

// d(w1, w2)/d(seeds) for a kernel called as kernel(b1, b2, w1, w2) on seeded poses.
template <class Kernel>
Mat12 element_jacobian(const Pose<Ad12>& b1, const Pose<Ad12>& b2, Kernel&& kernel) {
  Vec6T<Ad12> w1 = Vec6T<Ad12>::Zero(), w2 = Vec6T<Ad12>::Zero();
  kernel(b1, b2, w1, w2);
  Mat12 j;
  for (int r = 0; r < 6; ++r) {
    j.row(r) = w1(r).derivatives().transpose();
    j.row(6 + r) = w2(r).derivatives().transpose();
  }
  return j;
}

}  // namespace beamrail
