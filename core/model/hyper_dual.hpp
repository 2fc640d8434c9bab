// Hyper-dual numbers: x = v + a e1 + b e2 + ab e1 e2 with e1^2 = e2^2 = 0 (e1 e2 != 0). A function
// evaluated on them carries its value, its derivatives along two directions and the mixed second
// derivative, all exact to rounding:
//   f(v + a e1 + b e2 + ab e1 e2) = f + f' a e1 + f' b e2 + (f' ab + f'' a b) e1 e2.
// The design sensitivities (core/analysis/sensitivity.hpp) seed e2 with a design parameter (and
// the state's derivative along it) and e1 with a mode shape: the e1 e2 part of the generalized
// forces is then d/dp of the tangent stiffness applied to the mode, with no difference quotient.
// Works as an Eigen scalar.
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "core/model/derivative_scalar.hpp"

namespace beamrail {

struct HyperDual {
  double v = 0.0, a = 0.0, b = 0.0, ab = 0.0;

  HyperDual() = default;
  HyperDual(double value) : v(value) {}  // NOLINT: constants convert implicitly, as in Eigen code
  HyperDual(double value, double e1, double e2, double e12) : v(value), a(e1), b(e2), ab(e12) {}

  double value() const { return v; }

  HyperDual& operator+=(const HyperDual& y) {
    v += y.v, a += y.a, b += y.b, ab += y.ab;
    return *this;
  }
  HyperDual& operator-=(const HyperDual& y) {
    v -= y.v, a -= y.a, b -= y.b, ab -= y.ab;
    return *this;
  }
  HyperDual& operator*=(const HyperDual& y) {
    ab = v * y.ab + a * y.b + b * y.a + ab * y.v;
    a = v * y.a + a * y.v;
    b = v * y.b + b * y.v;
    v *= y.v;
    return *this;
  }
  HyperDual& operator*=(double s) {
    v *= s, a *= s, b *= s, ab *= s;
    return *this;
  }
  HyperDual& operator/=(const HyperDual& y);
};

// f(x) from f(v), f'(v) and f''(v).
inline HyperDual hyper_dual_chain(const HyperDual& x, double f, double d1, double d2) {
  return {f, d1 * x.a, d1 * x.b, d1 * x.ab + d2 * x.a * x.b};
}

inline HyperDual operator-(const HyperDual& x) { return {-x.v, -x.a, -x.b, -x.ab}; }
inline HyperDual operator+(HyperDual x, const HyperDual& y) { return x += y; }
inline HyperDual operator-(HyperDual x, const HyperDual& y) { return x -= y; }
inline HyperDual operator*(HyperDual x, const HyperDual& y) { return x *= y; }
inline HyperDual operator+(HyperDual x, double s) { return x += HyperDual(s); }
inline HyperDual operator+(double s, HyperDual x) { return x += HyperDual(s); }
inline HyperDual operator-(HyperDual x, double s) { return x -= HyperDual(s); }
inline HyperDual operator-(double s, const HyperDual& x) { return -x + s; }
inline HyperDual operator*(HyperDual x, double s) { return x *= s; }
inline HyperDual operator*(double s, HyperDual x) { return x *= s; }

inline HyperDual reciprocal(const HyperDual& x) {
  const double r = 1.0 / x.v;
  return hyper_dual_chain(x, r, -r * r, 2.0 * r * r * r);
}
inline HyperDual& HyperDual::operator/=(const HyperDual& y) { return *this *= reciprocal(y); }
inline HyperDual operator/(HyperDual x, const HyperDual& y) { return x /= y; }
inline HyperDual operator/(HyperDual x, double s) { return x *= 1.0 / s; }
inline HyperDual operator/(double s, const HyperDual& x) { return reciprocal(x) * s; }

// Comparisons look at the value (branches follow the value, as with doubles).
#define BEAMRAIL_HYPER_DUAL_COMPARE(op)                                                  \
  inline bool operator op(const HyperDual& x, const HyperDual& y) { return x.v op y.v; } \
  inline bool operator op(const HyperDual& x, double y) { return x.v op y; }             \
  inline bool operator op(double x, const HyperDual& y) { return x op y.v; }
BEAMRAIL_HYPER_DUAL_COMPARE(<)
BEAMRAIL_HYPER_DUAL_COMPARE(>)
BEAMRAIL_HYPER_DUAL_COMPARE(<=)
BEAMRAIL_HYPER_DUAL_COMPARE(>=)
BEAMRAIL_HYPER_DUAL_COMPARE(==)
BEAMRAIL_HYPER_DUAL_COMPARE(!=)
#undef BEAMRAIL_HYPER_DUAL_COMPARE

// sqrt at 0 has no derivative: a constant 0 (the norm of a zero vector) stays a constant 0.
inline HyperDual sqrt(const HyperDual& x) {
  if (x.v == 0.0 && x.a == 0.0 && x.b == 0.0 && x.ab == 0.0) return {};
  const double r = std::sqrt(x.v);
  return hyper_dual_chain(x, r, 0.5 / r, -0.25 / (r * x.v));
}
inline HyperDual abs(const HyperDual& x) { return x.v < 0.0 ? -x : x; }
inline HyperDual sin(const HyperDual& x) {
  return hyper_dual_chain(x, std::sin(x.v), std::cos(x.v), -std::sin(x.v));
}
inline HyperDual cos(const HyperDual& x) {
  return hyper_dual_chain(x, std::cos(x.v), -std::sin(x.v), -std::cos(x.v));
}
inline HyperDual exp(const HyperDual& x) {
  const double e = std::exp(x.v);
  return hyper_dual_chain(x, e, e, e);
}
// atan2(y, x) with its gradient (x, -y) / r^2 and Hessian [[-2xy, y^2 - x^2], [y^2 - x^2, 2xy]] /
// r^4 (rows and columns y, x).
inline HyperDual atan2(const HyperDual& y, const HyperDual& x) {
  const double r2 = x.v * x.v + y.v * y.v, r4 = r2 * r2;
  const double fy = x.v / r2, fx = -y.v / r2;
  const double fyy = -2.0 * x.v * y.v / r4, fxx = -fyy, fxy = (y.v * y.v - x.v * x.v) / r4;
  return {
      std::atan2(y.v, x.v), fy * y.a + fx * x.a, fy * y.b + fx * x.b,
      fy * y.ab + fx * x.ab + fyy * y.a * y.b + fxx * x.a * x.b + fxy * (y.a * x.b + x.a * y.b)};
}

}  // namespace beamrail

namespace Eigen {
template <>
struct NumTraits<beamrail::HyperDual>
    : beamrail::DerivativeScalarTraits<beamrail::HyperDual, 4, 9> {};
template <typename BinaryOp>
struct ScalarBinaryOpTraits<beamrail::HyperDual, double, BinaryOp> {
  using ReturnType = beamrail::HyperDual;
};
template <typename BinaryOp>
struct ScalarBinaryOpTraits<double, beamrail::HyperDual, BinaryOp> {
  using ReturnType = beamrail::HyperDual;
};
}  // namespace Eigen
