// Time functions that scale a load's magnitude or a prescribed motion's velocity: constant, step,
// ramp, smooth ramp, harmonic, or a table. Their
// numbers are of the model's scalar S (double, or a dual number for the design sensitivities: the
// factor then carries its derivative with respect to the function's parameters).
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace beamrail {

template <class S>
struct TimeFunctionT {
  enum class Type { kConstant, kStep, kRamp, kSmoothRamp, kHarmonic, kTable };
  Type type = Type::kConstant;
  S at = 0.0;    // step: the factor is 0 before `at` and 1 from `at` on [s]
  S from = 0.0;  // ramp: 0 before `from`, linear to 1 at `to`, then 1 [s]
  S to = 0.0;    // ramp end [s]
  // smooth ramp: 0 before `from`, s - sin(2 pi s) / (2 pi) with s = (t - from) / (to - from), 1
  // after `to`: its slope and curvature are continuous (zero at both ends)
  S frequency = 0.0;  // harmonic: sin(2 pi frequency t + phase) [Hz]
  S phase = 0.0;      // harmonic phase [rad]
  std::vector<S> t;   // table: strictly increasing times [s]
  std::vector<S> v;   // table: factors at those times; linear between, held outside

  // The factor at time `time`.
  S operator()(double time) const {
    using std::sin;
    switch (type) {
      case Type::kConstant:
        return S(1.0);
      case Type::kStep:
        return S(time >= at ? 1.0 : 0.0);
      case Type::kRamp:
        if (time <= from) return S(0.0);
        if (time >= to) return S(1.0);
        return (time - from) / (to - from);
      case Type::kSmoothRamp: {
        if (time <= from) return S(0.0);
        if (time >= to) return S(1.0);
        const S s = (time - from) / (to - from);
        return s - sin(2.0 * std::numbers::pi * s) / (2.0 * std::numbers::pi);
      }
      case Type::kHarmonic:
        return sin(2.0 * std::numbers::pi * frequency * time + phase);
      case Type::kTable: {
        if (time <= t.front()) return v.front();
        if (time >= t.back()) return v.back();
        const auto it =
            std::upper_bound(t.begin(), t.end(), time, [](double a, const S& b) { return a < b; });
        const size_t k = static_cast<size_t>(it - t.begin());
        const S s = (time - t[k - 1]) / (t[k] - t[k - 1]);
        return v[k - 1] + s * (v[k] - v[k - 1]);
      }
    }
    return S(1.0);
  }

  // The integral of the factor from 0 to `time` (a prescribed motion's displacement or angle per
  // unit velocity) [s], in closed form: the antiderivative G below, G(time) - G(0).
  S integral(double time) const { return antiderivative(time) - antiderivative(0.0); }

  // Appends the times where the factor or its slope jumps (integrators stop there; doubles only).
  void append_breakpoints(std::vector<double>& times) const {
    switch (type) {
      case Type::kStep:
        times.push_back(at);
        break;
      case Type::kRamp:
        times.push_back(from);
        times.push_back(to);
        break;
      case Type::kTable:
        times.insert(times.end(), t.begin(), t.end());
        break;
      default:
        break;
    }
  }

 private:
  // An antiderivative of the factor (any constant).
  S antiderivative(double time) const {
    using std::cos;
    using std::sin;
    constexpr double kTwoPi = 2.0 * std::numbers::pi;
    switch (type) {
      case Type::kConstant:
        return S(time);
      case Type::kStep:
        return time >= at ? time - at : S(0.0);
      case Type::kRamp:
      case Type::kSmoothRamp: {
        if (time <= from) return S(0.0);
        const S width = to - from;
        if (time >= to) return 0.5 * width + (time - to);
        const S s = (time - from) / width;
        if (type == Type::kRamp) return 0.5 * width * s * s;
        return width * (0.5 * s * s + (cos(kTwoPi * s) - 1.0) / (kTwoPi * kTwoPi));
      }
      case Type::kHarmonic:
        return -cos(kTwoPi * frequency * time + phase) / (kTwoPi * frequency);
      case Type::kTable: {
        // Held at v.front() before t.front(): G = v0 (time - t0) there; trapezoids between knots.
        if (time <= t.front()) return v.front() * (time - t.front());
        S sum = 0.0;
        for (size_t k = 1; k < t.size(); ++k) {
          if (time <= t[k]) {
            const S end = (*this)(time);
            return sum + 0.5 * (v[k - 1] + end) * (time - t[k - 1]);
          }
          sum += 0.5 * (v[k - 1] + v[k]) * (t[k] - t[k - 1]);
        }
        return sum + v.back() * (time - t.back());
      }
    }
    return S(time);
  }
};
using TimeFunction = TimeFunctionT<double>;

}  // namespace beamrail
