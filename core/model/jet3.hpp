// Third-order jets in three nilpotent directions: x = sum over subsets s of {e1, e2, e3} of
// c[s] e_s, with e_i^2 = 0 (c[0] the value, c[1] the e1 part, c[2] e2, c[3] e1 e2, c[4] e3,
// c[5] e1 e3, c[6] e2 e3, c[7] e1 e2 e3). A function evaluated on them carries every mixed
// derivative up to the third, exact to rounding: with n = x - c[0] (n^4 = 0),
//   f(x) = f + f' n + f'' n^2 / 2 + f''' n^3 / 6.
// The buckling factors' design derivatives (core/analysis/sensitivity.hpp) need the derivative
// along the design direction (e2) of the second derivative of the generalized forces along a mode
// (e1) and the load's displacement (e3). Works as an Eigen scalar.
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "core/model/derivative_scalar.hpp"

namespace beamrail {

struct Jet3 {
  double c[8] = {0, 0, 0, 0, 0, 0, 0, 0};

  Jet3() = default;
  Jet3(double value) { c[0] = value; }  // NOLINT: constants convert implicitly, as in Eigen code

  double value() const { return c[0]; }

  Jet3& operator+=(const Jet3& y) {
    for (int s = 0; s < 8; ++s) c[s] += y.c[s];
    return *this;
  }
  Jet3& operator-=(const Jet3& y) {
    for (int s = 0; s < 8; ++s) c[s] -= y.c[s];
    return *this;
  }
  Jet3& operator*=(double k) {
    for (int s = 0; s < 8; ++s) c[s] *= k;
    return *this;
  }
  // (x y)[s] = sum over the subsets a of s of x[a] y[s \ a].
  Jet3& operator*=(const Jet3& y) {
    Jet3 r;
    for (int s = 0; s < 8; ++s)
      for (int a = s;; a = (a - 1) & s) {
        r.c[s] += c[a] * y.c[s ^ a];
        if (a == 0) break;
      }
    return *this = r;
  }
  Jet3& operator/=(const Jet3& y);
};

// f(x) from f(v) and its first three derivatives at v = x.c[0].
inline Jet3 jet3_chain(const Jet3& x, double f, double d1, double d2, double d3) {
  Jet3 n = x;
  n.c[0] = 0.0;
  Jet3 n2 = n;
  n2 *= n;
  Jet3 n3 = n2;
  n3 *= n;
  Jet3 r;
  for (int s = 0; s < 8; ++s) r.c[s] = d1 * n.c[s] + 0.5 * d2 * n2.c[s] + d3 / 6.0 * n3.c[s];
  r.c[0] = f;
  return r;
}

inline Jet3 operator-(Jet3 x) { return x *= -1.0; }
inline Jet3 operator+(Jet3 x, const Jet3& y) { return x += y; }
inline Jet3 operator-(Jet3 x, const Jet3& y) { return x -= y; }
inline Jet3 operator*(Jet3 x, const Jet3& y) { return x *= y; }
inline Jet3 operator+(Jet3 x, double k) { return x += Jet3(k); }
inline Jet3 operator+(double k, Jet3 x) { return x += Jet3(k); }
inline Jet3 operator-(Jet3 x, double k) { return x -= Jet3(k); }
inline Jet3 operator-(double k, const Jet3& x) { return -x + k; }
inline Jet3 operator*(Jet3 x, double k) { return x *= k; }
inline Jet3 operator*(double k, Jet3 x) { return x *= k; }

inline Jet3 reciprocal(const Jet3& x) {
  const double r = 1.0 / x.c[0];
  return jet3_chain(x, r, -r * r, 2.0 * r * r * r, -6.0 * r * r * r * r);
}
inline Jet3& Jet3::operator/=(const Jet3& y) { return *this *= reciprocal(y); }
inline Jet3 operator/(Jet3 x, const Jet3& y) { return x /= y; }
inline Jet3 operator/(Jet3 x, double k) { return x *= 1.0 / k; }
inline Jet3 operator/(double k, const Jet3& x) { return reciprocal(x) * k; }

// Comparisons look at the value (branches follow the value, as with doubles).
#define BEAMRAIL_JET3_COMPARE(op)                                                    \
  inline bool operator op(const Jet3& x, const Jet3& y) { return x.c[0] op y.c[0]; } \
  inline bool operator op(const Jet3& x, double y) { return x.c[0] op y; }           \
  inline bool operator op(double x, const Jet3& y) { return x op y.c[0]; }
BEAMRAIL_JET3_COMPARE(<)
BEAMRAIL_JET3_COMPARE(>)
BEAMRAIL_JET3_COMPARE(<=)
BEAMRAIL_JET3_COMPARE(>=)
BEAMRAIL_JET3_COMPARE(==)
BEAMRAIL_JET3_COMPARE(!=)
#undef BEAMRAIL_JET3_COMPARE

// sqrt at 0 has no derivative: a constant 0 (the norm of a zero vector) stays a constant 0.
inline Jet3 sqrt(const Jet3& x) {
  bool constant = true;
  for (int s = 1; s < 8; ++s) constant = constant && x.c[s] == 0.0;
  if (x.c[0] == 0.0 && constant) return {};
  const double r = std::sqrt(x.c[0]), v = x.c[0];
  return jet3_chain(x, r, 0.5 / r, -0.25 / (r * v), 0.375 / (r * v * v));
}
inline Jet3 abs(const Jet3& x) { return x.c[0] < 0.0 ? -x : x; }
inline Jet3 sin(const Jet3& x) {
  const double s = std::sin(x.c[0]), c = std::cos(x.c[0]);
  return jet3_chain(x, s, c, -s, -c);
}
inline Jet3 cos(const Jet3& x) {
  const double s = std::sin(x.c[0]), c = std::cos(x.c[0]);
  return jet3_chain(x, c, -s, -c, s);
}
inline Jet3 exp(const Jet3& x) {
  const double e = std::exp(x.c[0]);
  return jet3_chain(x, e, e, e, e);
}
// atan2(y, x) = atan2(y0, x0) + atan(z), z = (x0 y - y0 x) / (x0 x + y0 y) nilpotent (its value
// is 0): atan(z) = z - z^3 / 3.
inline Jet3 atan2(const Jet3& y, const Jet3& x) {
  const double x0 = x.c[0], y0 = y.c[0];
  Jet3 z = (x0 * y - y0 * x) / (x0 * x + y0 * y);
  z.c[0] = 0.0;
  Jet3 z3 = z * z * z;
  Jet3 r = z - z3 / 3.0;
  r.c[0] = std::atan2(y0, x0);
  return r;
}

}  // namespace beamrail

namespace Eigen {
template <>
struct NumTraits<beamrail::Jet3> : beamrail::DerivativeScalarTraits<beamrail::Jet3, 8, 27> {};
template <typename BinaryOp>
struct ScalarBinaryOpTraits<beamrail::Jet3, double, BinaryOp> {
  using ReturnType = beamrail::Jet3;
};
template <typename BinaryOp>
struct ScalarBinaryOpTraits<double, beamrail::Jet3, BinaryOp> {
  using ReturnType = beamrail::Jet3;
};
}  // namespace Eigen
