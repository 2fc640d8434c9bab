#include "core/analysis/element_deformation.hpp"

#include <algorithm>
#include <cmath>

#include "core/model/element_kinematics.hpp"
#include "core/model/element_tangent.hpp"
#include "core/model/rotation.hpp"

namespace beamrail {

ElementDeformation::ElementDeformation(const Model& model, const Data& data) {
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  const auto extend = [&](const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  };
  for (int i : model.free_bodies) extend(centre(model, data, i));
  const auto add = [&](const ElementEnds& ends, bool rail, RotationMeasure measure) {
    const ElementFrames<double> f =
        element_frames(ends, data.pose[ends.body1], data.pose[ends.body2], measure);
    const bool twist_free = measure == RotationMeasure::kAnglesTwistFree;
    const Vec3 c1 = centre(model, data, ends.body1);
    extend(c1 + f.R1);
    extend(c1 + f.lever1);
    Row row;
    row.k1 = model.bodies[ends.body1].free_index;
    row.k2 = model.bodies[ends.body2].free_index;
    if (row.k1 < 0 && row.k2 < 0) return;
    row.j = kinematic_map(f);
    row.counts = {!rail, true, true, !twist_free, true, true};
    rows_.push_back(row);
  };
  for (const Beam& e : model.beams) add(e.ends, false, rotation_measure(e));
  for (const Rail& e : model.rails) add(e.ends, true, rotation_measure(e));
  for (const Joint& e : model.joints) {
    Row row;
    row.k1 = model.bodies[e.body1].free_index;
    row.k2 = model.bodies[e.body2].free_index;
    const Vec3 c1 = centre(model, data, e.body1), c2 = centre(model, data, e.body2);
    const Vec3 r1 = data.pose[e.body1].A * e.r1, r2 = data.pose[e.body2].A * e.r2;
    extend(c1 + r1);
    extend(c2 + r2);
    if (row.k1 < 0 && row.k2 < 0) continue;
    // Rows in the joint frame carried by body 1: column 0 is a revolute joint's axis.
    const Mat3 ft = (data.pose[e.body1].A * e.frame1).transpose();
    row.j.setZero();
    row.j.block<3, 3>(0, 0) = -ft;
    row.j.block<3, 3>(0, 3) = ft * skew<double>(r1);
    row.j.block<3, 3>(0, 6) = ft;
    row.j.block<3, 3>(0, 9) = -ft * skew<double>(r2);
    row.j.block<3, 3>(3, 3) = -ft;
    row.j.block<3, 3>(3, 9) = ft;
    const bool turns = e.type != JointType::kSpherical;
    row.counts = {true, true, true, e.type == JointType::kFixed, turns, turns};
    row.joint = true;
    const double c = e.relative_compliance;
    row.weight = c > 0.0 ? std::min(1.0, kRigidModeDeformation / std::sqrt(c)) : 1.0;
    rows_.push_back(row);
  }
  const double extent = model.n_free() > 0 ? (hi - lo).norm() : 0.0;
  length_ = extent > 0.0 && std::isfinite(extent) ? extent : 1.0;
}

double ElementDeformation::worst(const Eigen::VectorXd& x, bool joints) const {
  double motion = 0.0;
  for (Eigen::Index k = 0; k < x.size() / kDofsPerBody; ++k)
    motion = std::max(motion, x.segment<3>(kDofsPerBody * k).norm() / length_ +
                                  x.segment<3>(kDofsPerBody * k + 3).norm());
  if (motion == 0.0) return 0.0;
  double worst = 0.0;
  for (const Row& r : rows_) {
    if (r.joint && !joints) continue;
    Eigen::Matrix<double, 12, 1> local = Eigen::Matrix<double, 12, 1>::Zero();
    if (r.k1 >= 0) local.head<6>() = x.segment<kDofsPerBody>(kDofsPerBody * r.k1);
    if (r.k2 >= 0) local.tail<6>() = x.segment<kDofsPerBody>(kDofsPerBody * r.k2);
    const Vec6 d = r.j * local;
    double xi = 0.0, phi = 0.0;
    for (int c = 0; c < 3; ++c) {
      if (r.counts[c]) xi += d(c) * d(c);
      if (r.counts[3 + c]) phi += d(3 + c) * d(3 + c);
    }
    worst = std::max(worst, r.weight * (std::sqrt(xi) / length_ + std::sqrt(phi)));
  }
  return worst / motion;
}

}  // namespace beamrail
