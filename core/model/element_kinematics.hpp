// Kinematics shared by beams and rails (docs/model.md "Beams", steps 1-4): the element frame
// carried by each end, the deformation measured in the left-end frame, its rate, and the map from a
// deformation gradient to the wrenches on the two bodies.
//
// Deformation coordinates: xi = E1^T (p2 - p1) (position of point 2 in the left-end frame) and
// phi, a measure of the relative rotation a = E1^T E2 (RotationMeasure): its rotation vector
// log(a) (beams under the energy law), or the paper's three angles
// (atan2(a32, a22), atan2(a13, a33), atan2(a21, a11)) (paper law, rails). A global rotation
// increment theta_i of body i and a displacement dc_i of its centre change them by
//   d xi  = E1^T (dc2 - dc1 - R2 x theta2 + (p2 - c1) x theta1)
//   d phi = T E1^T (theta2 - theta1),
// where T (3 x 3) is the derivative of phi with respect to a small rotation of the
// right end expressed in the left-end frame. A force law given as a gradient g = dU/d(xi, phi) thus
// yields the generalized forces -dU/d(c, theta) of both bodies (apply_deformation_gradient).
//
// The paper's phi_y comes from the third column of A, so a large twist about the element axis
// leaks into it. An element that must let the right end turn freely about its axis (a cylindrical
// rail) takes both bending angles from the first column instead, the direction of the right end's
// axis: phi_y = atan2(-a31, a11), phi_z = atan2(a21, a11). Both definitions agree to first order.
// The three angles differ from the rotation vector at second order where twist and bending combine:
// a segment of length h of a rod with uniform twist tau and curvature kappa about z has
// a = exp(h [(tau, 0, kappa)]x), whose rotation vector is exactly h (tau, 0, kappa), while the
// angles give phi_y = h^2 tau kappa / 2, a bending moment of order h per segment: segmented rods
// converged at first order in three dimensions with the angles, at second with the rotation
// vector (tests/core/analysis/rotation_convergence_test.cpp).
#pragma once

#include <algorithm>
#include <cmath>

#include "core/model/model.hpp"
#include "core/model/rotation.hpp"

namespace beamrail {

// How an element measures the relative rotation a = E1^T E2 of its ends.
enum class RotationMeasure {
  kAngles,           // the paper's three atan2 angles (paper-law beams, prismatic rails)
  kAnglesTwistFree,  // both bending angles from the first column of a (cylindrical rails)
  kRotationVector,   // the rotation vector log(a) (energy-law beams)
};

template <class P>
RotationMeasure rotation_measure(const BeamT<P>& beam) {
  return beam.formulation == Formulation::kEnergy ? RotationMeasure::kRotationVector
                                                  : RotationMeasure::kAngles;
}
template <class P>
RotationMeasure rotation_measure(const RailT<P>& rail) {
  return rail.type == RailType::kCylindrical ? RotationMeasure::kAnglesTwistFree
                                             : RotationMeasure::kAngles;
}

// The largest element angle |phi_i| inside the range of the laws on the atan2 angles [rad]: their
// derivative T is singular at a bending angle of pi/2, and the law repeats where an angle passes
// pi (core/analysis/deformation_check.hpp says what the analyses do beyond it).
inline constexpr double kElementAngleLimit = 1.5;
// The largest rotation angle |phi| inside the range of the law on the rotation vector [rad]: the
// rotation vector is single-valued and smooth below pi (where it jumps to the opposite axis), and
// T stays regular up to 2 pi.
inline constexpr double kRotationVectorLimit = 3.0;

inline double angle_limit(RotationMeasure measure) {
  return measure == RotationMeasure::kRotationVector ? kRotationVectorLimit : kElementAngleLimit;
}

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
  Vec3T<T> phi;     // rotation measure of the right end in the left-end frame [rad]
  Mat3T<T> t;       // d phi / d (small rotation of the right end in the left-end frame)
};

// The paper's atan2 angles phi of a relative rotation a and T = d phi / d (small rotation of the
// right end in the left-end frame); twist_free: both bending angles from the first column.
template <class T>
void relative_angles(const Mat3T<T>& a, bool twist_free, Vec3T<T>& phi, Mat3T<T>& t) {
  using std::atan2;
  phi(0) = atan2(a(2, 1), a(1, 1));
  phi(1) = twist_free ? atan2(-a(2, 0), a(0, 0)) : atan2(a(0, 2), a(2, 2));
  phi(2) = atan2(a(1, 0), a(0, 0));
  const T nx = a(1, 1) * a(1, 1) + a(2, 1) * a(2, 1);
  const T nz = a(0, 0) * a(0, 0) + a(1, 0) * a(1, 0);
  t(0, 0) = T(1), t(0, 1) = -a(0, 1) * a(1, 1) / nx, t(0, 2) = -a(0, 1) * a(2, 1) / nx;
  t(2, 0) = -a(0, 0) * a(2, 0) / nz, t(2, 1) = -a(1, 0) * a(2, 0) / nz, t(2, 2) = T(1);
  if (twist_free) {
    const T n = a(0, 0) * a(0, 0) + a(2, 0) * a(2, 0);
    t(1, 0) = -a(0, 0) * a(1, 0) / n, t(1, 1) = T(1), t(1, 2) = -a(1, 0) * a(2, 0) / n;
  } else {
    const T ny = a(0, 2) * a(0, 2) + a(2, 2) * a(2, 2);
    t(1, 0) = -a(0, 2) * a(1, 2) / ny, t(1, 1) = T(1), t(1, 2) = -a(1, 2) * a(2, 2) / ny;
  }
}

// The rotation vector phi = log(a) of a relative rotation a (angle theta = |phi| < pi) and
// T = d phi / d delta for a' = exp([delta]x) a (a small rotation delta of the right end in the
// left-end frame): the inverse of the left Jacobian of exp,
//   T = I - 1/2 [phi]x + c [phi]x^2,  c = (1 - (theta/2) cot(theta/2)) / theta^2
//                                         = 1/12 + theta^2/720 + theta^4/30240 + ...
// (exp([delta]x) exp([phi]x) = exp([phi + T delta]x) to first order in delta). From
// cos theta = (tr a - 1) / 2 and the axial vector w = 2 sin theta n of a - a^T:
// phi = theta / (2 sin theta) w and (theta/2) cot(theta/2) = theta / (2 sin theta) (1 + cos theta).
// Near theta = 0 both factors come from series in sin^2 theta and theta^2, so that no square root
// of zero reaches a derivative-carrying scalar (T = I and its derivatives are exact at a = I).
template <class T>
void relative_rotation_vector(const Mat3T<T>& a, Vec3T<T>& phi, Mat3T<T>& t) {
  using std::atan2;
  using std::sqrt;
  const Vec3T<T> w(a(2, 1) - a(1, 2), a(0, 2) - a(2, 0), a(1, 0) - a(0, 1));
  const T cos_theta = T(0.5) * (a(0, 0) + a(1, 1) + a(2, 2) - 1.0);
  const T sin2 = T(0.25) * w.squaredNorm();
  T half_ratio;  // theta / (2 sin theta)
  if (sin2 < 1e-4 && cos_theta > 0.0) {
    // asin(s) / s = 1 + s^2/6 + 3 s^4/40 + 5 s^6/112 + 35 s^8/1152 + O(s^10): s^10 < 1e-20.
    half_ratio =
        0.5 + sin2 * (1.0 / 12 + sin2 * (3.0 / 80 + sin2 * (5.0 / 224 + sin2 * (35.0 / 2304))));
  } else {
    const T sin_theta = sqrt(sin2);
    half_ratio = T(0.5) * atan2(sin_theta, cos_theta) / sin_theta;
  }
  phi = half_ratio * w;
  const T theta2 = phi.squaredNorm();
  T c;
  if (theta2 < 1e-2) {
    // sum |B_2k| theta^(2k-2) / (2k)! over k >= 1, to theta^8: the next term is 5e-20 of c.
    c = 1.0 / 12 +
        theta2 * (1.0 / 720 +
                  theta2 * (1.0 / 30240 + theta2 * (1.0 / 1209600 + theta2 * (1.0 / 47900160))));
  } else {
    c = (1.0 - half_ratio * (1.0 + cos_theta)) / theta2;
  }
  const Mat3T<T> px = skew<T>(phi);
  t = Mat3T<T>::Identity() - T(0.5) * px + c * (px * px);
}

// phi and T of the relative rotation a in the element's measure.
template <class T>
void relative_rotation(const Mat3T<T>& a, RotationMeasure measure, Vec3T<T>& phi, Mat3T<T>& t) {
  if (measure == RotationMeasure::kRotationVector)
    relative_rotation_vector(a, phi, t);
  else
    relative_angles(a, measure == RotationMeasure::kAnglesTwistFree, phi, t);
}

// The ends' numbers are of a scalar P: double, or the scalar T of the poses (design sensitivities).
template <class P, class T>
ElementFrames<T> element_frames(const ElementEndsT<P>& ends, const Pose<T>& b1, const Pose<T>& b2,
                                RotationMeasure measure) {
  ElementFrames<T> f;
  f.E1 = b1.A * ends.frame1;
  const Mat3T<T> e2 = b2.A * ends.frame2;
  f.R1 = b1.A * ends.r1;
  f.R2 = b2.A * ends.r2;
  f.lever1 = ends.centre_offset.template cast<T>() + (b2.u - b1.u) + f.R2;  // p2 - c1
  // The chord p2 - p1 with the displacements added last: the levers of a fixed body at the
  // origin to points far from it cancel against the reference centres' offset (exactly, as the
  // body does not turn), so the chord keeps the displacements' precision wherever the element
  // sits (lever1 - R1 rounded them to eps |p2 - c1|: a cantilever on the ground 300 m from the
  // origin took 3,400 times bdf's steps at the origin, its stiff rotary mode's forces noisy).
  f.xi = f.E1.transpose() * ((ends.centre_offset.template cast<T>() - f.R1 + f.R2) + (b2.u - b1.u));
  f.a = f.E1.transpose() * e2;
  relative_rotation(f.a, measure, f.phi, f.t);
  return f;
}

// The element's angle as its range is judged [rad]: |phi| for the rotation vector, the largest
// |phi_i| for the atan2 angles (a cylindrical rail's free twist excluded).
inline double element_angle(const ElementFrames<double>& f, RotationMeasure measure) {
  if (measure == RotationMeasure::kRotationVector) return f.phi.norm();
  const double bending = std::max(std::abs(f.phi(1)), std::abs(f.phi(2)));
  return measure == RotationMeasure::kAnglesTwistFree ? bending
                                                      : std::max(bending, std::abs(f.phi(0)));
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
