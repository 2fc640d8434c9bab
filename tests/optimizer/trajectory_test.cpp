// Trajectory errors at the library level (optimizer/run/trajectory.hpp): the largest distance
// between two runs' body centres over their common samples, relative to the largest distance a
// reference body moved from its start; NaN when nothing can be compared.
#include "optimizer/run/trajectory.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace beamrail {
namespace {

// Two bodies: the first moves along x by 0.1 per sample, the second along y by 0.05.
Trajectory moving(int samples) {
  Trajectory t;
  t.bodies = {3, 5};
  for (int k = 0; k < samples; ++k) {
    t.times.push_back(0.01 * k);
    t.positions.push_back(Vec3(0.1 * k, 0.0, 0.0));
    t.positions.push_back(Vec3(0.0, 0.05 * k, 1.0));
  }
  return t;
}

TEST(Trajectory, TheErrorIsTheLargestDistanceOverTheLargestMotion) {
  const Trajectory reference = moving(11);  // the first body moves 1.0 at most
  Trajectory run = moving(11);
  run.positions[2 * 4 + 1] += Vec3(0.0, 3e-3, 4e-3);  // the second body at sample 4: 5e-3 off
  run.positions[2 * 7] += Vec3(1e-3, 0.0, 0.0);       // the first at sample 7: 1e-3 off
  EXPECT_NEAR(trajectory_error(run, reference), 5e-3, 1e-15);  // rounding of unit positions
  EXPECT_EQ(trajectory_error(reference, reference), 0.0);
}

TEST(Trajectory, OnlyTheCommonSamplesAreCompared) {
  const Trajectory reference = moving(11);
  Trajectory run = moving(6);
  run.positions[2 * 5] += Vec3(0.0, 0.0, 2e-3);
  EXPECT_NEAR(trajectory_error(run, reference), 2e-3, 1e-15);
}

TEST(Trajectory, NothingToCompareIsNaN) {
  const Trajectory reference = moving(11);
  EXPECT_TRUE(std::isnan(trajectory_error(moving(0), reference)));
  Trajectory other = moving(11);
  other.bodies.pop_back();
  EXPECT_TRUE(std::isnan(trajectory_error(other, reference)));
  const Trajectory still = moving(1);  // a reference that does not move
  EXPECT_TRUE(std::isnan(trajectory_error(still, still)));
}

}  // namespace
}  // namespace beamrail
