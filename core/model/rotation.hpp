// Rotations: Euler parameters (unit quaternions, scalar first), rotation matrices, skew matrices
// and the small-rotation increments ("rotation vectors") used as generalized coordinates.
//
// Conventions: A(q) maps body axes to global axes. A rotation increment theta (global axes) changes
// A to exp([theta]x) A, which in Euler parameters is q -> quat(theta) (x) q.
#pragma once

#include <cmath>

#include "core/model/types.hpp"

namespace beamrail {

// The matrix [v]x with [v]x w = v x w.
template <class T>
Mat3T<T> skew(const Vec3T<T>& v) {
  Mat3T<T> s;
  s << T(0), -v(2), v(1), v(2), T(0), -v(0), -v(1), v(0), T(0);
  return s;
}

// Body-to-global rotation matrix of the Euler parameters q; q need not be normalized (q/|q| is
// used).
template <class T>
Mat3T<T> rotation_matrix(const Vec4T<T>& q_raw) {
  using std::sqrt;
  const Vec4T<T> q = q_raw / sqrt(q_raw.squaredNorm());
  const T q0 = q(0), q1 = q(1), q2 = q(2), q3 = q(3);
  Mat3T<T> a;
  a << q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3, T(2) * (q1 * q2 - q0 * q3),
      T(2) * (q1 * q3 + q0 * q2), T(2) * (q1 * q2 + q0 * q3), q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3,
      T(2) * (q2 * q3 - q0 * q1), T(2) * (q1 * q3 - q0 * q2), T(2) * (q2 * q3 + q0 * q1),
      q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3;
  return a;
}

// Quaternion product a (x) b.
inline Vec4 quat_multiply(const Vec4& a, const Vec4& b) {
  Vec4 r;
  r(0) = a(0) * b(0) - a.tail<3>().dot(b.tail<3>());
  r.tail<3>() = a(0) * b.tail<3>() + b(0) * a.tail<3>() + a.tail<3>().cross(b.tail<3>());
  return r;
}

// The angle of the rotation from orientation a to orientation b [rad, 0 .. pi]: Euler parameters of
// either sign and any norm (2 atan2(|vec r|, |r0|), r = conj(a) (x) b, accurate at small angles).
inline double rotation_angle_between(const Vec4& a, const Vec4& b) {
  const Vec4 r = quat_multiply(Vec4(a(0), -a(1), -a(2), -a(3)), b);
  return 2.0 * std::atan2(r.tail<3>().norm(), std::abs(r(0)));
}

// Euler parameters of the rotation exp([theta]x) (angle |theta| about theta/|theta|).
inline Vec4 quat_from_rotation_vector(const Vec3& theta) {
  const double angle = theta.norm();
  Vec4 q;
  if (angle < 1e-8) {
    // Second-order series; exact to rounding below 1e-8 rad.
    q(0) = 1.0 - angle * angle / 8.0;
    q.tail<3>() = 0.5 * theta;
  } else {
    q(0) = std::cos(0.5 * angle);
    q.tail<3>() = std::sin(0.5 * angle) / angle * theta;
  }
  return q;
}

// Euler parameters of a proper rotation matrix (Shepperd's method), q0 >= 0.
template <class T>
Vec4T<T> quaternion_of(const Mat3T<T>& a) {
  using std::sqrt;
  const T tr = a.trace();
  Vec4T<T> q;
  if (tr >= a(0, 0) && tr >= a(1, 1) && tr >= a(2, 2)) {
    const T s = 2.0 * sqrt(1.0 + tr);
    q << 0.25 * s, (a(2, 1) - a(1, 2)) / s, (a(0, 2) - a(2, 0)) / s, (a(1, 0) - a(0, 1)) / s;
  } else if (a(0, 0) >= a(1, 1) && a(0, 0) >= a(2, 2)) {
    const T s = 2.0 * sqrt(1.0 + 2.0 * a(0, 0) - tr);
    q << (a(2, 1) - a(1, 2)) / s, 0.25 * s, (a(0, 1) + a(1, 0)) / s, (a(0, 2) + a(2, 0)) / s;
  } else if (a(1, 1) >= a(2, 2)) {
    const T s = 2.0 * sqrt(1.0 + 2.0 * a(1, 1) - tr);
    q << (a(0, 2) - a(2, 0)) / s, (a(0, 1) + a(1, 0)) / s, 0.25 * s, (a(1, 2) + a(2, 1)) / s;
  } else {
    const T s = 2.0 * sqrt(1.0 + 2.0 * a(2, 2) - tr);
    q << (a(1, 0) - a(0, 1)) / s, (a(0, 2) + a(2, 0)) / s, (a(1, 2) + a(2, 1)) / s, 0.25 * s;
  }
  if (q(0) < 0.0) q = -q;
  return q / q.norm();
}
inline Vec4 quat_from_rotation_matrix(const Mat3& a) { return quaternion_of<double>(a); }

// The rotation vector of a proper rotation matrix (inverse of exp), angle in [0, pi].
inline Vec3 rotation_vector(const Mat3& a) {
  const Vec4 q = quat_from_rotation_matrix(a);
  const double s = q.tail<3>().norm();
  if (s < 1e-12) return 2.0 * q.tail<3>();
  return 2.0 * std::atan2(s, q(0)) / s * q.tail<3>();
}

// The rotation vector of a that is nearest `near` among its equivalents (angle + 2 pi k about the
// same axis, any integer k): follows a rotation continuously through pi when `near` is the
// previous rotation vector plus the increment since.
inline Vec3 rotation_vector_near(const Mat3& a, const Vec3& near) {
  constexpr double kTwoPi = 2.0 * 3.14159265358979323846;
  const Vec3 r = rotation_vector(a);
  double angle = r.norm();
  Vec3 axis;
  if (angle > 1e-12) {
    axis = r / angle;
  } else if (near.norm() > 0.5 * kTwoPi) {
    axis = near.normalized();  // a whole number of turns about the axis of `near`
    angle = 0.0;
  } else {
    return r;
  }
  const double turns = std::round((near.dot(axis) - angle) / kTwoPi);
  return (angle + kTwoPi * turns) * axis;
}

// d(theta)/dq: the global rotation increment produced by a change dq of (unnormalized) Euler
// parameters, theta = 2 vec(dq (x) q*) / |q|^2  (3 x 4).
inline Mat34 rotation_increment_jacobian(const Vec4& q) {
  Mat34 h;
  h.col(0) = -q.tail<3>();
  h.rightCols<3>() = q(0) * Mat3::Identity() + skew<double>(q.tail<3>());
  return (2.0 / q.squaredNorm()) * h;
}

// The 4 x 3 matrix Q(q) with q (x) (0, w) = Q(q) w.
inline Mat43 quat_left_product_matrix(const Vec4& q) {
  Mat43 m;
  m.row(0) = -q.tail<3>().transpose();
  m.bottomRows<3>() = q(0) * Mat3::Identity() + skew<double>(q.tail<3>());
  return m;
}

// The 4 x 4 matrix R(w) with q (x) (0, w) = R(w) q.
inline Mat4 quat_right_product_matrix(const Vec3& w) {
  Mat4 m;
  m(0, 0) = 0.0;
  m.block<1, 3>(0, 1) = -w.transpose();
  m.block<3, 1>(1, 0) = w;
  m.block<3, 3>(1, 1) = -skew<double>(w);
  return m;
}

// The rotation vector theta of A = exp([theta]x) A0 and its rates. With the global angular
// velocity omega (dA/dt = [omega]x A) and the left Jacobian J(theta) of SO(3),
//   omega = J(theta) dtheta/dt,
//   J(theta)     = I + (1 - cos a)/a^2 [theta]x + (a - sin a)/a^3 [theta]x^2,   a = |theta|,
//   J(theta)^-1  = I - 1/2 [theta]x + c(a) [theta]x^2,
//   c(a) = 1/a^2 - (1 + cos a) / (2 a sin a) = 1/12 + a^2/720 + a^4/30240 + a^6/1209600 + ...
// (valid for |theta| < 2 pi).
namespace rotation_detail {

// c(a) and dc/d(a^2) of the inverse left Jacobian at s = a^2. The closed form of the derivative
// cancels as 1/a^3 against a: below s = 1/4 the series (from the Laurent series of cot; at
// s = 1/4 its truncation error is 2.5e-16 relative in c, 4.2e-13 in dc/ds) is used for both.
inline void inverse_jacobian_coefficient(double s, double* c, double* dc_ds) {
  if (s < 0.25) {
    constexpr double k[7] = {1.0 / 12.0,         1.0 / 720.0,      1.0 / 30240.0,
                             1.0 / 1209600.0,    1.0 / 47900160.0, 1382.0 / 2615348736000.0,
                             1.0 / 74724249600.0};
    *c = k[0] + s * (k[1] + s * (k[2] + s * (k[3] + s * (k[4] + s * (k[5] + s * k[6])))));
    *dc_ds =
        k[1] + s * (2 * k[2] + s * (3 * k[3] + s * (4 * k[4] + s * (5 * k[5] + s * 6 * k[6]))));
    return;
  }
  const double a = std::sqrt(s), half_cot = 1.0 / std::tan(0.5 * a),
               csc2 = 1.0 / (std::sin(0.5 * a) * std::sin(0.5 * a));
  *c = 1.0 / s - half_cot / (2.0 * a);  // (1 + cos a) / sin a = cot(a/2)
  const double dc_da = -2.0 / (s * a) + csc2 / (4.0 * a) + half_cot / (2.0 * s);
  *dc_ds = dc_da / (2.0 * a);
}

}  // namespace rotation_detail

// d theta / dt when the body turns at the global angular velocity omega: J(theta)^-1 omega.
inline Vec3 rotation_vector_rate(const Vec3& theta, const Vec3& omega) {
  double c, dc_ds;
  rotation_detail::inverse_jacobian_coefficient(theta.squaredNorm(), &c, &dc_ds);
  const Vec3 tw = theta.cross(omega);
  return omega - 0.5 * tw + c * theta.cross(tw);
}

// The global angular velocity of a body whose rotation vector changes at theta_rate:
// J(theta) theta_rate (the inverse of rotation_vector_rate).
inline Vec3 angular_velocity(const Vec3& theta, const Vec3& theta_rate) {
  const double s = theta.squaredNorm();
  double b, d;  // (1 - cos a)/a^2, (a - sin a)/a^3
  if (s < 0.25) {
    // Series (alternating, terms falling by s/(2k(2k+1)) or faster): the first omitted terms are
    // below 5e-18 of b and d at s = 1/4. Above, the closed forms lose at most 30 ulps (a >= 0.5).
    constexpr double kb[7] = {1.0 / 2,       1.0 / 24,        1.0 / 720,          1.0 / 40320,
                              1.0 / 3628800, 1.0 / 479001600, 1.0 / 87178291200.0};
    constexpr double kd[7] = {
        1.0 / 6,        1.0 / 120,          1.0 / 5040,           1.0 / 362880,
        1.0 / 39916800, 1.0 / 6227020800.0, 1.0 / 1307674368000.0};
    b = kb[6];
    d = kd[6];
    for (int k = 5; k >= 0; --k) {
      b = kb[k] - s * b;
      d = kd[k] - s * d;
    }
  } else {
    const double a = std::sqrt(s);
    b = (1.0 - std::cos(a)) / s;
    d = (a - std::sin(a)) / (s * a);
  }
  const Vec3 tv = theta.cross(theta_rate);
  return theta_rate + b * tv + d * theta.cross(tv);
}

// d^2 theta / dt^2 from the angular acceleration d omega / dt (global axes):
// d/dt [J(theta)^-1 omega] = J^-1 domega/dt + (d/dtheta [J^-1 omega]) dtheta/dt, with
// omega = J(theta) theta_rate.
inline Vec3 rotation_vector_acceleration(const Vec3& theta, const Vec3& theta_rate,
                                         const Vec3& omega_rate) {
  double c, dc_ds;
  rotation_detail::inverse_jacobian_coefficient(theta.squaredNorm(), &c, &dc_ds);
  const Vec3 omega = angular_velocity(theta, theta_rate);
  const Vec3 tw = theta.cross(omega), ta = theta.cross(omega_rate);
  return omega_rate - 0.5 * ta + c * theta.cross(ta)  // J^-1 domega/dt
         - 0.5 * theta_rate.cross(omega) +
         c * (theta_rate.cross(tw) + theta.cross(theta_rate.cross(omega))) +
         2.0 * dc_ds * theta.dot(theta_rate) * theta.cross(tw);
}

}  // namespace beamrail
