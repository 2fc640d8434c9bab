// Time functions that scale a load's magnitude: constant, step, ramp, harmonic, or a table. Their
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
  enum class Type { kConstant, kStep, kRamp, kHarmonic, kTable };
  Type type = Type::kConstant;
  S at = 0.0;         // step: the factor is 0 before `at` and 1 from `at` on [s]
  S from = 0.0;       // ramp: 0 before `from`, linear to 1 at `to`, then 1 [s]
  S to = 0.0;         // ramp end [s]
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
};
using TimeFunction = TimeFunctionT<double>;

}  // namespace beamrail
