// Kinematics shared by beams and rails (docs/model.md "Beams", steps 1-4): the element frame
// carried by each end, the deformation measured in the left-end frame, its rate, and the map from a
// deformation gradient to the wrenches on the two bodies.
//
// Deformation coordinates: xi = E1^T (p2 - p1) (position of point 2 in the left-end frame) and
// phi = (atan2(a32, a22), atan2(a13, a33), atan2(a21, a11)) of A = E1^T E2. A global rotation
// increment theta_i of body i and a displacement dc_i of its centre change them by
//   d xi  = E1^T (dc2 - dc1 - R2 x theta2 + (p2 - c1) x theta1)
//   d phi = T E1^T (theta2 - theta1),
// where T (3 x 3) is the derivative of the three angles with respect to a small rotation of the
// right end expressed in the left-end frame. A force law given as a gradient g = dU/d(xi, phi) thus
// yields the generalized forces -dU/d(c, theta) of both bodies (apply_deformation_gradient).
//
// The paper's phi_y comes from the third column of A, so a large twist about the element axis
// leaks into it. An element that must let the right end turn freely about its axis (a cylindrical
// rail) takes both bending angles from the first column instead, the direction of the right end's
// axis: phi_y = atan2(-a31, a11), phi_z = atan2(a21, a11). Both definitions agree to first order.
#pragma once

#include <cmath>

#include "core/model/model.hpp"
#include "core/model/rotation.hpp"

namespace beamrail {

// The largest element angle |phi_i| inside the range of the element laws [rad]: the angles'
// derivative T is singular at a bending angle of pi/2, and the law repeats where an angle passes
// pi (core/analysis/deformation_check.hpp says what the analyses do beyond it).
inline constexpr double kElementAngleLimit = 1.5;

// Position, orientation and velocity of a body, all in global axes. The centre is held as its
// displacement u from the body's reference position (in a Model: Body::position, the initial
// centre), never as absolute coordinates: an element's chord is the difference of its bodies'
// reference centres (ElementEnds::centre_offset, a constant) plus u2 - u1, which keeps the
// precision of the displacements however far the bodies are from the origin. Absolute coordinates
// would round the chord of a short element to eps |c|, which a stiff element turns into large
// forces.
template <class T>
struct Pose {
  Vec3T<T> u;      // displacement of the centre of mass from the reference position [m]
  Mat3T<T> A;      // body -> global rotation
  Vec3T<T> v;      // velocity of the centre [m/s]
  Vec3T<T> omega;  // angular velocity, global axes [rad/s]
};

template <class T>
struct ElementFrames {
  Mat3T<T> E1;      // element frame carried by the left end (global)
  Vec3T<T> R1, R2;  // centre -> attachment point, global [m]
  Vec3T<T> lever1;  // p2 - c1 [m]
  Vec3T<T> xi;      // E1^T (p2 - p1) [m]
  Mat3T<T> a;       // relative rotation E1^T E2
  Vec3T<T> phi;     // rotation angles of the right end in the left-end frame [rad]
  Mat3T<T> t;       // d phi / d (small rotation of the right end in the left-end frame)
};

// The rotation angles phi of a relative rotation a and T = d phi / d (small rotation of the right
// end in the left-end frame); twist_free: both bending angles from the first column.
template <class T>
void relative_angles(const Mat3T<T>& a, bool twist_free, Vec3T<T>& phi, Mat3T<T>& t) {
  using std::atan2;
  phi << atan2(a(2, 1), a(1, 1)), atan2(a(0, 2), a(2, 2)), atan2(a(1, 0), a(0, 0));
  const T nx = a(1, 1) * a(1, 1) + a(2, 1) * a(2, 1);
  const T nz = a(0, 0) * a(0, 0) + a(1, 0) * a(1, 0);
  t(0, 0) = T(1), t(0, 1) = -a(0, 1) * a(1, 1) / nx, t(0, 2) = -a(0, 1) * a(2, 1) / nx;
  t(2, 0) = -a(0, 0) * a(2, 0) / nz, t(2, 1) = -a(1, 0) * a(2, 0) / nz, t(2, 2) = T(1);
  if (twist_free) {
    const T n = a(0, 0) * a(0, 0) + a(2, 0) * a(2, 0);
    phi(1) = atan2(-a(2, 0), a(0, 0));
    t(1, 0) = -a(0, 0) * a(1, 0) / n, t(1, 1) = T(1), t(1, 2) = -a(1, 0) * a(2, 0) / n;
  } else {
    const T ny = a(0, 2) * a(0, 2) + a(2, 2) * a(2, 2);
    t(1, 0) = -a(0, 2) * a(1, 2) / ny, t(1, 1) = T(1), t(1, 2) = -a(1, 2) * a(2, 2) / ny;
  }
}

template <class T>
ElementFrames<T> element_frames(const ElementEnds& ends, const Pose<T>& b1, const Pose<T>& b2,
                                bool twist_free_bending = false) {
  ElementFrames<T> f;
  f.E1 = b1.A * ends.frame1;
  const Mat3T<T> e2 = b2.A * ends.frame2;
  f.R1 = b1.A * ends.r1;
  f.R2 = b2.A * ends.r2;
  f.lever1 = ends.centre_offset.template cast<T>() + (b2.u - b1.u) + f.R2;  // p2 - c1
  f.xi = f.E1.transpose() * (f.lever1 - f.R1);
  f.a = f.E1.transpose() * e2;
  relative_angles(f.a, twist_free_bending, f.phi, f.t);
  return f;
}

// Rate of the deformation coordinates (d xi/dt, d phi/dt).
template <class T>
Vec6T<T> deformation_rate(const ElementFrames<T>& f, const Pose<T>& b1, const Pose<T>& b2) {
  Vec6T<T> rate;
  rate.template head<3>() =
      f.E1.transpose() * (b2.v - b1.v - f.R2.cross(b2.omega) + f.lever1.cross(b1.omega));
  rate.template tail<3>() = f.t * (f.E1.transpose() * (b2.omega - b1.omega));
  return rate;
}

// Adds the generalized forces -dU/d(c, theta) of a gradient g = dU/d(xi, phi) to the wrenches
// (force, moment about the centre of mass; global axes) on body 1 and body 2.
template <class T>
void apply_deformation_gradient(const ElementFrames<T>& f, const Vec6T<T>& g, Vec6T<T>& w1,
                                Vec6T<T>& w2) {
  const Vec3T<T> force = f.E1 * g.template head<3>();
  const Vec3T<T> moment = f.E1 * (f.t.transpose() * g.template tail<3>());
  w1.template head<3>() += force;
  w1.template tail<3>() += f.lever1.cross(force) + moment;
  w2.template head<3>() -= force;
  w2.template tail<3>() -= f.R2.cross(force) + moment;
}

// Adds the paper's end wrenches (steps 11-14): P1, P2 are the local end vectors K1 delta and
// K2 delta; body 1 gets force F2 and moment R1 x F2 - M1, body 2 gets -F2 and -(R2 x F2) - M2.
template <class T>
void apply_paper_end_wrenches(const ElementFrames<T>& f, const Vec6T<T>& p1, const Vec6T<T>& p2,
                              Vec6T<T>& w1, Vec6T<T>& w2) {
  const Vec3T<T> force = f.E1 * p2.template head<3>();
  const Vec3T<T> m1 = f.E1 * p1.template tail<3>();
  const Vec3T<T> m2 = f.E1 * p2.template tail<3>();
  w1.template head<3>() += force;
  w1.template tail<3>() += f.R1.cross(force) - m1;
  w2.template head<3>() -= force;
  w2.template tail<3>() -= f.R2.cross(force) + m2;
}

}  // namespace beamrail
