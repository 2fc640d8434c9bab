// Designs whose analyses warn (here: a rod bent beyond the beam law's small-angle range) through
// the real command line: sweep and history rows count the warnings and carry their texts, and an
// optimization counts a warned design as infeasible unless "warned_designs": "accept".
#include <gtest/gtest.h>
#include <stdlib.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/support/study_runs.hpp"

#ifndef BEAMRAIL_EXECUTABLE
#error "BEAMRAIL_EXECUTABLE must name the beamrail binary"
#endif

namespace beamrail {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using testing::read_table;
using testing::read_text;
using testing::Table;

// A 1 m steel rod cantilever of diameter d under a 50 N m tip torque: it turns the tip by
// theta = M L / (E I), I = pi d^4 / 64, and the beam's relative rotation is that angle. Past
// 0.5 rad the analysis warns. The lightest rod with theta <= 1 rad has d = 8.35 mm (theta = 1, a
// warned design); the lightest without a warning has d = 9.93 mm (theta = 0.5).
constexpr const char* kBentRod = R"({
  "name": "bent_rod",
  "scene": {
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"rod": {"shape": "circle", "diameter": 0.03}},
    "bodies": [{"name": "tip", "mass": 1.0, "inertia": [1e-3, 1e-3, 1e-3], "position": [1, 0, 0]}],
    "beams": [{"name": "rod", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "rod"}],
    "loads": [{"type": "torque", "body": "tip", "value": [0, 0, 50]}]
  },
  "analyses": [{"type": "static"}],
  "responses": {"turn": {"quantity": "rotation", "body": "tip", "axis": [0, 0, 1]},
                "mass": {"quantity": "mass"}},
  "study": {"type": "optimize",
            "variables": [{"name": "d", "pointer": "/scene/sections/rod/diameter",
                           "lower": 0.005, "upper": 0.05, "initial": 0.03}],
            "objective": {"minimize": "mass"},
            "constraints": [{"response": "turn", "<=": 1.0}],
            "algorithm": "LN_COBYLA", "max_evaluations": 100, "xtol_rel": 1e-8}
})";

// d at which the tip turns by theta.
double diameter_for(double theta) {
  const double inertia = 50.0 * 1.0 / (2.1e11 * theta);
  return std::pow(64.0 * inertia / M_PI, 0.25);
}

class WarnedDesigns : public testing::StudyRuns {
 protected:
  // Runs the study into `out`; it must succeed.
  void run_ok(const Json& study, const std::string& out) {
    StudyRuns::run_ok(write_study(out + ".json", study), out);
  }
};

TEST_F(WarnedDesigns, SweepRowsCountTheWarningsAndCarryTheirTexts) {
  Json s = Json::parse(kBentRod);
  s["study"] = Json::parse(R"({"type": "sweep", "sampling": "list",
      "variables": [{"name": "d", "pointer": "/scene/sections/rod/diameter"}],
      "rows": [[0.008], [0.012]]})");
  ASSERT_NO_FATAL_FAILURE(run_ok(s, "sweep"));
  const Table t = read_table(dir_ / "sweep" / "samples.csv");
  ASSERT_EQ(t.rows.size(), 2u);
  for (size_t i = 0; i < 2; ++i)
    std::printf("d %s: turn %s, %s, %s warnings, \"%s\"\n", t.at(i, "d").c_str(),
                t.at(i, "turn").c_str(), t.at(i, "status").c_str(), t.at(i, "warnings").c_str(),
                t.at(i, "message").c_str());
  // d = 8 mm turns 1.2 rad: a warned ok row; d = 12 mm turns 0.24 rad: a plain ok row.
  EXPECT_EQ(t.at(0, "status"), "ok");
  EXPECT_EQ(t.at(0, "warnings"), "1");
  EXPECT_EQ(
      t.at(0, "message").rfind("warning: beam \"rod\" deforms beyond the small-angle range", 0), 0u)
      << t.at(0, "message");
  EXPECT_EQ(t.at(1, "status"), "ok");
  EXPECT_EQ(t.at(1, "warnings"), "0");
  EXPECT_EQ(t.at(1, "message"), "");
  EXPECT_EQ(Json::parse(read_text(dir_ / "sweep" / "summary.json"))["designs_with_warnings"], 1);
}

// By default a warned design is infeasible: the best design is the lightest that turns at most
// 0.5 rad. With "accept", the lightest that turns at most 1 rad, a warned design.
TEST_F(WarnedDesigns, OptimizationCountsWarnedDesignsAsInfeasibleUnlessAccepted) {
  const Json study = Json::parse(kBentRod);
  ASSERT_NO_FATAL_FAILURE(run_ok(study, "strict"));
  Json accepting = study;
  accepting["study"]["warned_designs"] = "accept";
  ASSERT_NO_FATAL_FAILURE(run_ok(accepting, "accept"));

  const Json strict = Json::parse(read_text(dir_ / "strict" / "best.json"));
  const Json loose = Json::parse(read_text(dir_ / "accept" / "best.json"));
  const double d_strict = strict["variables"]["d"], d_loose = loose["variables"]["d"];
  std::printf(
      "best d: %.6g (turn %.4g) by default, %.6g (turn %.4g) accepting warnings; "
      "closed form %.6g and %.6g\n",
      d_strict, strict["responses"]["turn"].get<double>(), d_loose,
      loose["responses"]["turn"].get<double>(), diameter_for(0.5), diameter_for(1.0));
  EXPECT_LE(strict["responses"]["turn"].get<double>(), 0.5);
  EXPECT_NEAR(d_strict / diameter_for(0.5), 1.0, 1e-3);
  EXPECT_GT(loose["responses"]["turn"].get<double>(), 0.99);
  EXPECT_NEAR(d_loose / diameter_for(1.0), 1.0, 1e-3);

  // The warned designs are in both histories, infeasible only by default.
  for (const char* out : {"strict", "accept"}) {
    const Table t = read_table(dir_ / out / "history.csv");
    size_t warned = 0, warned_feasible = 0;
    for (size_t i = 0; i < t.rows.size(); ++i)
      if (t.at(i, "warnings") != "0") {
        ++warned;
        warned_feasible += t.at(i, "feasible") == "1";
        EXPECT_NE(t.at(i, "message").find("warning: beam \"rod\""), std::string::npos);
      }
    std::printf("%s: %zu of %zu designs warned, %zu of them feasible\n", out, warned, t.rows.size(),
                warned_feasible);
    EXPECT_GT(warned, 0u);
    if (std::string(out) == "strict")
      EXPECT_EQ(warned_feasible, 0u);
    else
      EXPECT_GT(warned_feasible, 0u);
    const Json summary = Json::parse(read_text(dir_ / out / "summary.json"));
    EXPECT_EQ(summary["designs_with_warnings"], warned);
    EXPECT_EQ(summary["warned_designs"], out == std::string("strict") ? "infeasible" : "accept");
  }
}

}  // namespace
}  // namespace beamrail
