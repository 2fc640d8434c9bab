// Trajectory errors at the library level (optimizer/run/trajectory.hpp): the largest distance
// between two runs' body centres over their common samples, relative to the largest distance a
// reference body moved from its start; NaN when nothing can be compared.
#include "optimizer/run/trajectory.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/model/data.hpp"
#include "core/model/rotation.hpp"
#include "tests/support/scenes.hpp"

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
  Trajectory rounding = moving(11);  // one that moves by rounding only
  for (size_t i = 0; i < rounding.positions.size(); ++i)
    rounding.positions[i] = Vec3(1e-17 * (i % 4), 0.0, 1.0);
  EXPECT_TRUE(std::isnan(trajectory_error(moving(11), rounding)));
}

// A body turning about z by 0.2 rad per sample (2 rad at most) and a still one; the run's first
// body is off by 1e-3 rad about x at sample 6, its second by 4e-4 rad about y at sample 2: the
// angle between the orientations (a closed form: (q p) relative to q is p) over the largest turn.
TEST(Trajectory, TheRotationErrorIsTheLargestAngleOverTheLargestTurn) {
  const auto turning = [](int samples) {
    Trajectory t = moving(samples);
    for (int k = 0; k < samples; ++k) {
      t.orientations.push_back(quat_from_rotation_vector(Vec3(0, 0, 0.2 * k)));
      t.orientations.push_back(Vec4(1, 0, 0, 0));
    }
    return t;
  };
  const Trajectory reference = turning(11);
  Trajectory run = turning(11);
  run.orientations[2 * 6] =
      quat_multiply(run.orientations[2 * 6], quat_from_rotation_vector(Vec3(1e-3, 0, 0)));
  run.orientations[2 * 2 + 1] = -quat_from_rotation_vector(Vec3(0, 4e-4, 0));  // either sign
  EXPECT_NEAR(trajectory_rotation_error(run, reference), 1e-3 / 2.0, 1e-15);
  EXPECT_EQ(trajectory_rotation_error(reference, reference), 0.0);
  // The centres agree: the position measure does not see it.
  EXPECT_EQ(trajectory_error(run, reference), 0.0);
  // Nothing to measure against: no orientations recorded, or no body turning beyond rounding
  // (1e-20 rad: a bar pulled along its axis), or an orientation that is not finite.
  EXPECT_TRUE(std::isnan(trajectory_rotation_error(moving(11), moving(11))));
  Trajectory still = turning(11);
  for (size_t i = 0; i < still.orientations.size(); ++i)
    still.orientations[i] = quat_from_rotation_vector(Vec3(0, 0, 1e-20 * (i % 3)));
  Trajectory still_run = still;
  still_run.orientations[5] = quat_from_rotation_vector(Vec3(3e-20, 0, 0));
  EXPECT_TRUE(std::isnan(trajectory_rotation_error(still_run, still)));
  Trajectory broken = run;
  broken.orientations[7](1) = std::nan("");
  EXPECT_TRUE(std::isnan(trajectory_rotation_error(broken, reference)));
}

// A run of more body samples than kTrajectoryBodySamples keeps every stride-th row from the
// first, the fewest rows that fit: 4 bodies over 2^19 rows (2^21 body samples) keep every second
// row, 2^18 rows every row; a row more than the cap keeps every second.
TEST(Trajectory, ALongRunKeepsEveryStrideThRowWithinTheCap) {
  std::string bodies;
  for (const char* name : {"a", "b", "c", "d"})
    bodies += std::string(bodies.empty() ? "" : ",") + R"({"name": ")" + name +
              R"(", "mass": 1, "inertia": [1, 1, 1], "position": [0, 0, 0]})";
  const Model model = testing::scene_from_json(R"({"bodies": [)" + bodies + "]}");
  ASSERT_EQ(model.n_free(), 4);
  EXPECT_EQ(trajectory_of(model).stride, 1);
  EXPECT_EQ(trajectory_of(model, kTrajectoryBodySamples / 4).stride, 1);
  EXPECT_EQ(trajectory_of(model, kTrajectoryBodySamples / 4 + 1).stride, 2);
  EXPECT_EQ(trajectory_of(model, kTrajectoryBodySamples / 2).stride, 2);
  EXPECT_EQ(trajectory_of(model, 3 * kTrajectoryBodySamples / 4).stride, 3);
  Trajectory t = trajectory_of(model, kTrajectoryBodySamples / 2);
  Data data(model);
  for (int k = 0; k < 7; ++k) {
    TransientSample s;
    s.t = 0.1 * k;
    t.record(s, data);
  }
  ASSERT_EQ(t.times.size(), 4u);  // rows 0, 2, 4, 6
  EXPECT_DOUBLE_EQ(t.times[3], 0.6);
  EXPECT_EQ(t.positions.size(), 16u);
}

}  // namespace
}  // namespace beamrail
