// Time functions that scale a load's magnitude: constant, step, ramp, harmonic, or a table.
#pragma once

#include <vector>

namespace beamrail {

struct TimeFunction {
  enum class Type { kConstant, kStep, kRamp, kHarmonic, kTable };
  Type type = Type::kConstant;
  double at = 0.0;         // step: the factor is 0 before `at` and 1 from `at` on [s]
  double from = 0.0;       // ramp: 0 before `from`, linear to 1 at `to`, then 1 [s]
  double to = 0.0;         // ramp end [s]
  double frequency = 0.0;  // harmonic: sin(2 pi frequency t + phase) [Hz]
  double phase = 0.0;      // harmonic phase [rad]
  std::vector<double> t;   // table: strictly increasing times [s]
  std::vector<double> v;   // table: factors at those times; linear between, held outside

  // The factor at time `time`.
  double operator()(double time) const;

  // Appends the times where the factor or its slope jumps (integrators stop there).
  void append_breakpoints(std::vector<double>& times) const;
};

}  // namespace beamrail
