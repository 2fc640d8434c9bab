#include "core/model/time_function.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace beamrail {

double TimeFunction::operator()(double time) const {
  switch (type) {
    case Type::kConstant:
      return 1.0;
    case Type::kStep:
      return time >= at ? 1.0 : 0.0;
    case Type::kRamp:
      if (time <= from) return 0.0;
      if (time >= to) return 1.0;
      return (time - from) / (to - from);
    case Type::kHarmonic:
      return std::sin(2.0 * std::numbers::pi * frequency * time + phase);
    case Type::kTable: {
      if (time <= t.front()) return v.front();
      if (time >= t.back()) return v.back();
      const auto it = std::upper_bound(t.begin(), t.end(), time);
      const size_t k = static_cast<size_t>(it - t.begin());
      const double s = (time - t[k - 1]) / (t[k] - t[k - 1]);
      return v[k - 1] + s * (v[k] - v[k - 1]);
    }
  }
  return 1.0;
}

void TimeFunction::append_breakpoints(std::vector<double>& times) const {
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

}  // namespace beamrail
