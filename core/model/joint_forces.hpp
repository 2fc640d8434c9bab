// What a joint carries, for the result tables, the VTK files and the responses (docs/model.md
// "Joints"): its end forces in the finite-element convention of core/model/element_forces.hpp (the
// force and moment acting ON the joint at each end, moments about the joint points), in the joint
// frame carried by body 1 (column 0 the axis of a revolute joint); its gap p2 - p1 and the angle
// by which the bodies turned against what it holds.
//
// On any scalar: doubles for the tables, hyper-dual numbers for the design sensitivities.
#pragma once

#include <cmath>
#include <vector>

#include "core/model/element_forces.hpp"
#include "core/model/joint.hpp"

namespace beamrail {

template <class S>
EndForcesT<S> joint_end_forces(const ModelT<S>& model, const std::vector<Pose<S>>& pose,
                               int index) {
  using element_forces_detail::at_rest;
  const JointT<S>& j = model.joints[index];
  const Pose<S> b1 = at_rest(pose[j.body1]), b2 = at_rest(pose[j.body2]);
  Vec6T<S> w1 = Vec6T<S>::Zero(), w2 = Vec6T<S>::Zero();
  joint_wrenches(j, b1, b2, w1, w2);
  const Mat3T<S> ft = (b1.A * j.frame1.template cast<S>()).transpose();
  const Vec3T<S> lever1 = b1.A * j.r1.template cast<S>(), lever2 = b2.A * j.r2.template cast<S>();
  const Vec3T<S> f1 = w1.template head<3>(), f2 = w2.template head<3>();
  EndForcesT<S> out;
  out.end1 << -ft * f1, -ft * (w1.template tail<3>() - lever1.cross(f1));
  out.end2 << -ft * f2, -ft * (w2.template tail<3>() - lever2.cross(f2));
  return out;
}

inline EndForces joint_end_forces(const Model& model, const Data& data, int index) {
  return joint_end_forces(model, data.pose, index);
}

// The gap p2 - p1 of the joint points, global [m].
template <class S>
Vec3T<S> joint_gap(const JointT<S>& j, const Pose<S>& b1, const Pose<S>& b2) {
  return joint_gap(j, b1, b2, Vec3T<S>(b1.A * j.r1.template cast<S>()),
                   Vec3T<S>(b2.A * j.r2.template cast<S>()));
}

// The angle [rad] between the axes a revolute joint keeps aligned, the angle of the relative
// rotation of a fixed joint's frames, 0 for a spherical joint (which holds no rotation).
inline double joint_angle(const Joint& j, const Pose<double>& b1, const Pose<double>& b2) {
  if (j.type == JointType::kSpherical) return 0.0;
  const Mat3 f1 = b1.A * j.frame1, f2 = b2.A * j.frame2;
  if (j.type == JointType::kRevolute)
    return std::atan2(f1.col(0).cross(f2.col(0)).norm(), f1.col(0).dot(f2.col(0)));
  const Mat3 relative = f1.transpose() * f2;
  // The rotation vector's length from the skew part and the trace: accurate at small angles.
  const Vec3 skew_part(relative(2, 1) - relative(1, 2), relative(0, 2) - relative(2, 0),
                       relative(1, 0) - relative(0, 1));
  return std::atan2(0.5 * skew_part.norm(), 0.5 * (relative.trace() - 1.0));
}

}  // namespace beamrail
