// The joint kernel (docs/model.md "Joints"): a stiff penalty element between two bodies.
//   gap g = p2 - p1 of the two bodies' joint points: U_t = 1/2 k_force |g|^2 (every type);
//   revolute: the axes a1, a2 (column 0 of each joint frame, global): U_r = k_moment (1 - a1.a2);
//   fixed: the three frame columns b1_i, b2_i: U_r = k_moment / 2 sum_i (1 - b1_i.b2_i).
// 1 - a.b is summed as |a - b|^2 / 2 (the same for unit vectors): near 1, a.b rounds to steps of
// 1.1e-16, which a stiff joint's k_moment made steps of energy (6.5e-7 J on a joint of relative
// compliance 1e-9: the energy check of a bob swinging 1 degree on it reported 0.0015 of its
// energy changed, even for an explicit run at rtol 1e-12).
// For a small relative rotation theta (perpendicular to the axis for a revolute joint) both
// rotational energies are k_moment theta^2 / 2: k_force and k_moment are the joint's stiffness.
// A turn of any size about a revolute joint's axis costs nothing, and no angle limit applies.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/model/element_kinematics.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// The gap p2 - p1 of the joint points (0 initially): the difference of their displacements, each
// the centre's plus the lever's turn A r - A0 r. Taken from positions instead, the gap of a joint
// 170 m from the origin carried the rounding of its coordinates (2e-14 m), which the penalty
// stiffness turned into forces of 1e-3 N (a pinned frame in 160 segments, whose arc-length
// path then stalled at that residual); a fixed body's lever turns by exactly nothing.
template <class P, class T>
Vec3T<T> joint_gap(const JointT<P>& j, const Pose<T>& b1, const Pose<T>& b2, const Vec3T<T>& lever1,
                   const Vec3T<T>& lever2) {
  return (b2.u + (lever2 - j.lever2.template cast<T>())) -
         (b1.u + (lever1 - j.lever1.template cast<T>()));
}

// Adds the joint's wrenches on bodies 1 and 2 to w1 and w2 and returns its energy [J].
// The joint's numbers are of a scalar P: double, or T itself (design sensitivities).
template <class P, class T>
T joint_wrenches(const JointT<P>& j, const Pose<T>& b1, const Pose<T>& b2, Vec6T<T>& w1,
                 Vec6T<T>& w2) {
  const Vec3T<T> lever1 = b1.A * j.r1.template cast<T>(), lever2 = b2.A * j.r2.template cast<T>();
  const Vec3T<T> gap = joint_gap(j, b1, b2, lever1, lever2);
  const Vec3T<T> f2 = -j.k_force * gap;  // the force on body 2 at its joint point
  w2.template head<3>() += f2;
  w2.template tail<3>() += lever2.cross(f2);
  w1.template head<3>() -= f2;
  w1.template tail<3>() -= lever1.cross(f2);
  T energy = 0.5 * j.k_force * gap.squaredNorm();
  if (j.type == JointType::kSpherical) return energy;
  // U = c (1 - a1.a2): a turn dtheta2 of body 2 changes it by -c dtheta2.(a2 x a1), so the moment
  // on body 2 is c a2 x a1, and on body 1 c a1 x a2.
  const int columns = j.type == JointType::kRevolute ? 1 : 3;
  const P c = j.type == JointType::kRevolute ? j.k_moment : P(0.5 * j.k_moment);
  for (int i = 0; i < columns; ++i) {
    const Vec3T<T> a1 = b1.A * j.frame1.col(i).template cast<T>();
    const Vec3T<T> a2 = b2.A * j.frame2.col(i).template cast<T>();
    const Vec3T<T> m2 = c * a2.cross(a1);
    w2.template tail<3>() += m2;
    w1.template tail<3>() -= m2;
    energy += 0.5 * c * (a1 - a2).squaredNorm();
  }
  return energy;
}

// The scene's stiffness scale (translation [N/m], rotation [N m/rad]) that joints are made stiffer
// than: the stiffest element's end stiffness (EA/L, 12 EI/L^3; GJ/L, 4 EI/L). Without elements,
// the largest weight or force load over the joints' largest lever (the distance from a joint point
// to the centres of its bodies that are not fixed, 1 m when none): a joint then moves by
// relative_compliance times that lever under that load. The ground's "centre" is the origin, so
// its lever would make a joint softer the farther the scene sits from it (a pendulum 1e4 m away
// swung 21.5 mm off its 87 mm motion through a joint stretching 8 mm).
template <class S>
std::pair<S, S> joint_stiffness_scale(const ModelT<S>& model) {
  S kt = 0.0, kr = 0.0;
  const auto raise = [](S& to, const S& x) {
    if (x > to) to = x;
  };
  const auto element = [&](const S& ea, const S& gj, const S& eiy, const S& eiz, const S& l) {
    const S ei = eiy < eiz ? eiz : eiy;  // as std::max: eiy on a tie
    raise(kt, ea / l);
    raise(kt, 12.0 * ei / (l * l * l));
    raise(kr, gj / l);
    raise(kr, 4.0 * ei / l);
  };
  for (const BeamT<S>& e : model.beams) element(e.ea, e.gj, e.eiy, e.eiz, e.ends.length);
  for (const RailT<S>& e : model.rails) element(S(0.0), e.gj, e.eiy, e.eiz, e.ends.length);
  if (kt > 0.0 && kr > 0.0) return {kt, kr};
  S load = 0.0, lever = 0.0;
  for (const BodyT<S>& b : model.bodies)
    if (!b.fixed) raise(load, b.mass * model.gravity.norm());
  for (const LoadT<S>& l : model.loads)
    if (l.kind == LoadKind::kForce) raise(load, l.value.norm());
  for (const JointT<S>& j : model.joints) {
    if (!model.bodies[j.body1].fixed) raise(lever, j.r1.norm());
    if (!model.bodies[j.body2].fixed) raise(lever, j.r2.norm());
  }
  if (!(lever > 0.0)) lever = 1.0;
  if (!(load > 0.0)) load = 1.0;
  return {load / lever, load * lever};
}

}  // namespace beamrail
