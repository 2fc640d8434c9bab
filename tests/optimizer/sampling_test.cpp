// Sweep designs at the library level (optimizer/batch/sampling.hpp): the grid in index order (the
// last variable fastest, its range ending exactly on its upper bound), Latin hypercubes with one
// point in each stratum of every variable, the same for a seed, and list sweeps as given.
#include "optimizer/batch/sampling.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

namespace beamrail {
namespace {

DesignVariable range(double lower, double upper, int count = 0) {
  DesignVariable v;
  v.lower = lower;
  v.upper = upper;
  v.count = count;
  return v;
}

TEST(Sampling, TheGridVariesTheLastVariableFastest) {
  DesignVariable listed;
  listed.values = {7.0, -1.0};
  const std::vector<Design> d = grid_designs({listed, range(0.1, 0.7, 4)});
  ASSERT_EQ(d.size(), 8u);
  const double steps[] = {0.1, 0.1 + 0.6 / 3.0, 0.1 + 0.6 * 2.0 / 3.0, 0.7};
  for (size_t k = 0; k < d.size(); ++k) {
    ASSERT_EQ(d[k].size(), 2u);
    EXPECT_EQ(d[k][0], listed.values[k / 4]) << k;
    EXPECT_DOUBLE_EQ(d[k][1], steps[k % 4]) << k;
  }
  EXPECT_EQ(d[3][1], 0.7);  // the upper bound itself, not 0.1 + 3 * 0.2
}

TEST(Sampling, ALatinHypercubeHasOnePointInEveryStratumOfEveryVariable) {
  const std::vector<DesignVariable> v{range(0.0, 1.0), range(-3.0, 5.0), range(1e-3, 2e-3)};
  const int n = 37;
  const std::vector<Design> d = latin_hypercube(v, n, 11);
  ASSERT_EQ(d.size(), static_cast<size_t>(n));
  for (size_t j = 0; j < v.size(); ++j) {
    std::set<int> strata;
    for (const Design& x : d) {
      ASSERT_GE(x[j], v[j].lower);
      ASSERT_LT(x[j], v[j].upper);
      strata.insert(
          static_cast<int>(std::floor((x[j] - v[j].lower) / (v[j].upper - v[j].lower) * n)));
    }
    EXPECT_EQ(strata.size(), static_cast<size_t>(n)) << "variable " << j;
  }
  EXPECT_EQ(latin_hypercube(v, n, 11), d);
  EXPECT_NE(latin_hypercube(v, n, 12), d);
}

TEST(Sampling, AListSweepIsItsRowsAndAGridTheDefault) {
  DesignStudy study;
  study.variables = {range(0.0, 1.0, 3)};
  EXPECT_EQ(sweep_designs(study), grid_designs(study.variables));
  study.sweep.sampling = SweepPlan::Sampling::kList;
  study.sweep.rows = {{0.25}, {0.5}, {0.25}};
  EXPECT_EQ(sweep_designs(study), study.sweep.rows);
  study.sweep.sampling = SweepPlan::Sampling::kLhs;
  study.sweep.samples = 5;
  study.sweep.seed = 3;
  EXPECT_EQ(sweep_designs(study), latin_hypercube(study.variables, 5, 3));
}

}  // namespace
}  // namespace beamrail
