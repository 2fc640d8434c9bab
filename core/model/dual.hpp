// Forward-mode automatic differentiation: a value with N directional derivatives, stored in a
// fixed-size array so that arithmetic compiles to short straight-line loops (Eigen's AutoDiff
// module builds expression templates per operation and was 3x slower here; measured with
// tests/benchmarks/kernels_benchmark). Works as an Eigen scalar.
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "core/model/derivative_scalar.hpp"

namespace beamrail {

#define BEAMRAIL_DUAL_INLINE inline __attribute__((always_inline))

template <int N>
struct Dual {
  double v;
  double d[N];

  Dual() = default;                // uninitialized, like double: Eigen assigns before it reads
  Dual(double value) : v(value) {  // NOLINT: constants convert implicitly, as in Eigen code
    for (int i = 0; i < N; ++i) d[i] = 0.0;
  }
  // A variable: derivative 1 in direction k.
  Dual(double value, int k) : Dual(value) { d[k] = 1.0; }

  double value() const { return v; }

  BEAMRAIL_DUAL_INLINE Dual& operator+=(const Dual& b) {
    v += b.v;
    for (int i = 0; i < N; ++i) d[i] += b.d[i];
    return *this;
  }
  BEAMRAIL_DUAL_INLINE Dual& operator-=(const Dual& b) {
    v -= b.v;
    for (int i = 0; i < N; ++i) d[i] -= b.d[i];
    return *this;
  }
  BEAMRAIL_DUAL_INLINE Dual& operator*=(const Dual& b) {
    for (int i = 0; i < N; ++i) d[i] = d[i] * b.v + v * b.d[i];
    v *= b.v;
    return *this;
  }
  BEAMRAIL_DUAL_INLINE Dual& operator/=(const Dual& b) {
    const double inv = 1.0 / b.v, q = v * inv;
    for (int i = 0; i < N; ++i) d[i] = (d[i] - q * b.d[i]) * inv;
    v = q;
    return *this;
  }
  BEAMRAIL_DUAL_INLINE Dual& operator*=(double s) {
    v *= s;
    for (int i = 0; i < N; ++i) d[i] *= s;
    return *this;
  }
};

template <int N>
BEAMRAIL_DUAL_INLINE Dual<N> operator-(Dual<N> a) {
  a.v = -a.v;
  for (int i = 0; i < N; ++i) a.d[i] = -a.d[i];
  return a;
}
template <int N>
BEAMRAIL_DUAL_INLINE Dual<N> operator+(Dual<N> a, const Dual<N>& b) {
  return a += b;
}
template <int N>
BEAMRAIL_DUAL_INLINE Dual<N> operator-(Dual<N> a, const Dual<N>& b) {
  return a -= b;
}
template <int N>
BEAMRAIL_DUAL_INLINE Dual<N> operator*(Dual<N> a, const Dual<N>& b) {
  return a *= b;
}
template <int N>
BEAMRAIL_DUAL_INLINE Dual<N> operator/(Dual<N> a, const Dual<N>& b) {
  return a /= b;
}
template <int N>
BEAMRAIL_DUAL_INLINE Dual<N> operator+(Dual<N> a, double b) {
  a.v += b;
  return a;
}
template <int N>
BEAMRAIL_DUAL_INLINE Dual<N> operator+(double b, Dual<N> a) {
  a.v += b;
  return a;
}
template <int N>
BEAMRAIL_DUAL_INLINE Dual<N> operator-(Dual<N> a, double b) {
  a.v -= b;
  return a;
}
template <int N>
BEAMRAIL_DUAL_INLINE Dual<N> operator-(double b, const Dual<N>& a) {
  return -a + b;
}
template <int N>
BEAMRAIL_DUAL_INLINE Dual<N> operator*(Dual<N> a, double s) {
  return a *= s;
}
template <int N>
BEAMRAIL_DUAL_INLINE Dual<N> operator*(double s, Dual<N> a) {
  return a *= s;
}
template <int N>
BEAMRAIL_DUAL_INLINE Dual<N> operator/(Dual<N> a, double s) {
  return a *= 1.0 / s;
}
template <int N>
BEAMRAIL_DUAL_INLINE Dual<N> operator/(double s, const Dual<N>& b) {
  Dual<N> r;
  r.v = s / b.v;
  const double f = -r.v / b.v;
  for (int i = 0; i < N; ++i) r.d[i] = f * b.d[i];
  return r;
}

template <int N>
BEAMRAIL_DUAL_INLINE bool operator<(const Dual<N>& a, const Dual<N>& b) {
  return a.v < b.v;
}
template <int N>
BEAMRAIL_DUAL_INLINE bool operator>(const Dual<N>& a, const Dual<N>& b) {
  return a.v > b.v;
}
template <int N>
BEAMRAIL_DUAL_INLINE bool operator<=(const Dual<N>& a, const Dual<N>& b) {
  return a.v <= b.v;
}
template <int N>
BEAMRAIL_DUAL_INLINE bool operator>=(const Dual<N>& a, const Dual<N>& b) {
  return a.v >= b.v;
}
template <int N>
BEAMRAIL_DUAL_INLINE bool operator==(const Dual<N>& a, const Dual<N>& b) {
  return a.v == b.v;
}
template <int N>
BEAMRAIL_DUAL_INLINE bool operator!=(const Dual<N>& a, const Dual<N>& b) {
  return a.v != b.v;
}

// Comparisons with plain numbers look at the value.
#define BEAMRAIL_DUAL_COMPARE(op)                                     \
  template <int N>                                                    \
  BEAMRAIL_DUAL_INLINE bool operator op(const Dual<N>& a, double b) { \
    return a.v op b;                                                  \
  }                                                                   \
  template <int N>                                                    \
  BEAMRAIL_DUAL_INLINE bool operator op(double a, const Dual<N>& b) { \
    return a op b.v;                                                  \
  }
BEAMRAIL_DUAL_COMPARE(<)
BEAMRAIL_DUAL_COMPARE(>)
BEAMRAIL_DUAL_COMPARE(<=)
BEAMRAIL_DUAL_COMPARE(>=)
#undef BEAMRAIL_DUAL_COMPARE

template <int N>
BEAMRAIL_DUAL_INLINE Dual<N> sqrt(const Dual<N>& a) {
  Dual<N> r;
  r.v = std::sqrt(a.v);
  const double f = 0.5 / r.v;
  for (int i = 0; i < N; ++i) r.d[i] = f * a.d[i];
  return r;
}
template <int N>
BEAMRAIL_DUAL_INLINE Dual<N> abs(const Dual<N>& a) {
  return a.v < 0.0 ? -a : a;
}
template <int N>
BEAMRAIL_DUAL_INLINE Dual<N> atan2(const Dual<N>& y, const Dual<N>& x) {
  Dual<N> r;
  r.v = std::atan2(y.v, x.v);
  const double n = 1.0 / (x.v * x.v + y.v * y.v);
  const double fy = x.v * n, fx = -y.v * n;
  for (int i = 0; i < N; ++i) r.d[i] = fy * y.d[i] + fx * x.d[i];
  return r;
}

}  // namespace beamrail

namespace Eigen {
template <int N>
struct NumTraits<beamrail::Dual<N>> : beamrail::DerivativeScalarTraits<beamrail::Dual<N>, 2, 4> {};
template <int N, typename BinaryOp>
struct ScalarBinaryOpTraits<beamrail::Dual<N>, double, BinaryOp> {
  using ReturnType = beamrail::Dual<N>;
};
template <int N, typename BinaryOp>
struct ScalarBinaryOpTraits<double, beamrail::Dual<N>, BinaryOp> {
  using ReturnType = beamrail::Dual<N>;
};
}  // namespace Eigen
