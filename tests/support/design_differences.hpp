// The derivatives of a design's responses by finite differences: the independent check of the
// design sensitivities (tests/optimizer/*sensitivities_test.cpp).
#pragma once

#include <gtest/gtest.h>

#include <vector>

#include "optimizer/run/designs.hpp"

namespace beamrail::testing {

// d responses / d x_j at x: central differences at steps h and h / 2, extrapolated (Richardson:
// (4 D(h/2) - D(h)) / 3, error O(h^4) plus the analyses' rounding over the step). Each evaluation
// must end ok (a failed one is a test failure).
inline std::vector<double> extrapolated_differences(const DesignEvaluator& evaluator,
                                                    const std::vector<double>& x, size_t j,
                                                    double h, size_t responses) {
  const auto central = [&](double step) {
    std::vector<double> up = x, down = x;
    up[j] += step, down[j] -= step;
    const DesignOutcome u = evaluator.evaluate(up), d = evaluator.evaluate(down);
    EXPECT_EQ(u.status, Status::kOk) << u.message;
    EXPECT_EQ(d.status, Status::kOk) << d.message;
    std::vector<double> out(responses);
    for (size_t k = 0; k < responses; ++k) out[k] = (u.responses[k] - d.responses[k]) / (2 * step);
    return out;
  };
  const std::vector<double> a = central(h), b = central(h / 2);
  std::vector<double> out(responses);
  for (size_t k = 0; k < responses; ++k) out[k] = (4 * b[k] - a[k]) / 3;
  return out;
}

}  // namespace beamrail::testing
