// The arc-length study (studies/snap_through_truss.json) run by the beamrail command: its
// static_path.csv and summary.json against the truss's closed form (as in
// tests/core/analysis/static_path_test.cpp, here through the study file and the tables).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "optimizer/output/batch_table.hpp"
#include "tests/support/run_process.hpp"

namespace beamrail {
namespace {

namespace fs = std::filesystem;

// P(w) of the study's truss: a = 1 m, h = 0.1 m, EA = 1e6 N.
double truss_load(double w) {
  const double a = 1.0, h = 0.1, ea = 1e6;
  const double l0 = std::hypot(a, h), l = std::hypot(a, h - w);
  return 2.0 * ea * (l0 - l) / l0 * (h - w) / l;
}

TEST(StaticPathStudy, SnapThroughTrussPathAndLimitFollowTheClosedForm) {
  const fs::path dir = fs::temp_directory_path() / "beamrail_static_path_study";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path study = fs::path(BEAMRAIL_STUDIES_DIR) / "snap_through_truss.json";
  const testing::ProcessResult r =
      testing::run_process(BEAMRAIL_EXECUTABLE, {"run", study.string(), "-o", "out"}, dir);
  ASSERT_TRUE(r.exited && r.status == 0) << r.how << "\n" << r.err;
  std::ifstream csv(dir / "out" / "static_path.csv");
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  EXPECT_EQ(line, "point,load_factor,arc_length,iterations,body,dx,dy,dz,rx,ry,rz");
  // P_limit from the closed form (golden section on [0, h]).
  double lo = 0.0, hi = 0.1;
  for (int k = 0; k < 200; ++k) {
    const double m1 = hi - 0.618 * (hi - lo), m2 = lo + 0.618 * (hi - lo);
    if (truss_load(m1) < truss_load(m2))
      lo = m1;
    else
      hi = m2;
  }
  const double limit = truss_load(0.5 * (lo + hi)), load = 600.0;
  int apex_rows = 0;
  double worst = 0.0, last_factor = 0.0, last_w = 0.0, lowest = 0.0;
  while (std::getline(csv, line)) {
    const CsvRow row = parse_csv_line(line);
    ASSERT_EQ(row.size(), 11u) << line;
    if (row[4] != "apex") continue;
    ++apex_rows;
    const double factor = std::stod(row[1]), w = -std::stod(row[6]);
    worst = std::max(worst, std::abs(factor * load - truss_load(w)) / limit);
    lowest = std::min(lowest, factor);
    last_factor = factor;
    last_w = w;
  }
  const nlohmann::json summary =
      nlohmann::json::parse(testing::read_text(dir / "out" / "summary.json"));
  const nlohmann::json& a = summary["analyses"][0];
  std::printf(
      "snap-through study: %d path points, worst %.2e P_limit off P(w), limit load factor "
      "%.6f (closed form %.6f), lowest %.4f, final w %.6f m\n",
      apex_rows, worst, a["limit_load_factor"].get<double>(), limit / load, lowest, last_w);
  EXPECT_GT(apex_rows, 20);
  EXPECT_LT(worst, 5e-6);  // the joints' compliance (1e-6 of the bars' stiffness per joint)
  EXPECT_EQ(a["control"], "arc_length");
  EXPECT_NEAR(a["limit_load_factor"].get<double>(), limit / load, 1e-4 * limit / load);
  EXPECT_LT(lowest, -0.9 * limit / load);
  EXPECT_EQ(last_factor, 1.0);
  EXPECT_GT(last_w, 0.2);  // the inverted branch
  fs::remove_all(dir);
}

}  // namespace
}  // namespace beamrail
