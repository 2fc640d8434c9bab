// Random rigid motions and element geometries for property tests of the element kernels.
#pragma once

#include <random>

#include "core/model/element_kinematics.hpp"
#include "core/model/rotation.hpp"

namespace beamrail::testing {

class Random {
 public:
  explicit Random(unsigned seed) : engine_(seed) {}
  double uniform(double lo, double hi) { return std::uniform_real_distribution<>(lo, hi)(engine_); }
  Vec3 vec3(double scale) { return Vec3(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)) * scale; }
  // A rotation drawn uniformly over SO(3).
  Mat3 rotation() {
    std::normal_distribution<> n;
    Vec4 q(n(engine_), n(engine_), n(engine_), n(engine_));
    return rotation_matrix<double>(q);
  }

 private:
  std::mt19937 engine_;
};

// Pose of a body with centre c and rotation a, at rest.
inline Pose<double> pose(const Vec3& c, const Mat3& a, const Vec3& v = Vec3::Zero(),
                         const Vec3& omega = Vec3::Zero()) {
  return {c, a, v, omega};
}

// Element ends for points p1, p2 (p3 sets y) on bodies with the given initial poses.
inline ElementEnds make_ends(const Vec3& p1, const Vec3& p2, const Vec3& p3, const Pose<double>& b1,
                             const Pose<double>& b2) {
  ElementEnds e;
  e.body1 = 0, e.body2 = 1;
  const Vec3 x = (p2 - p1).normalized();
  const Vec3 y = ((p3 - p1) - (p3 - p1).dot(x) * x).normalized();
  Mat3 frame;
  frame << x, y, x.cross(y);
  e.r1 = b1.A.transpose() * (p1 - b1.u);
  e.r2 = b2.A.transpose() * (p2 - b2.u);
  e.frame1 = b1.A.transpose() * frame;
  e.frame2 = b2.A.transpose() * frame;
  e.length = (p2 - p1).norm();
  return e;
}

// Applies the rigid motion x -> rot x + shift to a pose (velocities rotate with it).
inline Pose<double> moved(const Pose<double>& p, const Mat3& rot, const Vec3& shift) {
  return {rot * p.u + shift, rot * p.A, rot * p.v, rot * p.omega};
}

// Rotates a pose by exp([theta]x) about its centre and shifts it by dc.
inline Pose<double> perturbed(const Pose<double>& p, const Vec3& dc, const Vec3& theta) {
  const Mat3 r = rotation_matrix<double>(quat_from_rotation_vector(theta));
  return {p.u + dc, r * p.A, p.v, p.omega};
}

}  // namespace beamrail::testing
