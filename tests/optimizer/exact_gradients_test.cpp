// Gradient optimizers on the design sensitivities, through the real command line: LD_ algorithms
// use the exact derivatives by default and reach the optimum of a closed form and of a 6-variable
// frame (COBYLA's, to 1e-6) in a fraction of the designs; "gradient": "fd" keeps differences,
// which step inside the bounds and never simulate a design twice; a design without exact
// derivatives falls back to differences with a warning; summary.json reports the problem NLopt
// sees (scaling) and how the gradients were made.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/run_process.hpp"

#ifndef BEAMRAIL_EXECUTABLE
#error "BEAMRAIL_EXECUTABLE must name the beamrail binary"
#endif
#ifndef BEAMRAIL_SOURCE_DIR
#error "BEAMRAIL_SOURCE_DIR must name the source tree"
#endif

namespace beamrail {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using testing::ProcessResult;
using testing::read_text;

const fs::path kSource = BEAMRAIL_SOURCE_DIR;

Json load_json(const fs::path& path) { return Json::parse(read_text(path)); }

// history.csv as rows of numbers (the columns before `status`), by column name.
struct History {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  double at(size_t row, const std::string& column) const {
    for (size_t c = 0; c < columns.size(); ++c)
      if (columns[c] == column) return rows[row][c];
    ADD_FAILURE() << "no column " << column;
    return NAN;
  }
};

History read_history(const fs::path& path) {
  History h;
  std::istringstream in(read_text(path));
  std::string line;
  std::getline(in, line);
  std::istringstream header(line);
  for (std::string c; std::getline(header, c, ',');) h.columns.push_back(c);
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::vector<double> row;
    for (std::string f; row.size() < h.columns.size() && std::getline(fields, f, ',');)
      row.push_back(std::strtod(f.c_str(), nullptr));
    h.rows.push_back(row);
  }
  return h;
}

class ExactGradients : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "beamrail_gradients_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  // Runs the study (written to dir_/name.json) into dir_/name; returns summary.json.
  Json run(const std::string& name, const Json& study) {
    std::ofstream(dir_ / (name + ".json")) << study.dump(2);
    const ProcessResult r = testing::run_process(
        BEAMRAIL_EXECUTABLE,
        {"run", (dir_ / (name + ".json")).string(), "-o", (dir_ / name).string(), "--quiet"}, dir_);
    EXPECT_TRUE(r.exited && r.status == 0) << name << ": " << r.how << "\n" << r.err;
    return load_json(dir_ / name / "summary.json");
  }
  fs::path dir_;
};

// The table frame: 6 section variables, minimum mass s.t. f1 >= 20 Hz and a deflection <= 0.3 mm.
TEST_F(ExactGradients, GradientOptimizersReachCobylasOptimumOfTheTableFrameInFewDesigns) {
  const Json frame = load_json(kSource / "tests/benchmarks/design_loop/table_frame.json");
  const Json cobyla = run("cobyla", frame);
  ASSERT_EQ(cobyla["status"], "ok");
  const double reference = cobyla["best"]["objective"];
  for (const std::string algorithm : {"LD_SLSQP", "LD_MMA"}) {
    Json study = frame;
    study["study"]["algorithm"] = algorithm;
    const Json s = run(algorithm, study);
    ASSERT_EQ(s["status"], "ok") << s["message"];
    const double objective = s["best"]["objective"];
    const int designs = s["designs_in_history"];
    std::printf("%s (exact derivatives): %.9f kg in %d designs; LN_COBYLA: %.9f kg in %d\n",
                algorithm.c_str(), objective, designs, reference,
                cobyla["designs_in_history"].get<int>());
    EXPECT_LT(objective / reference - 1, 1e-6);
    EXPECT_LE(designs, 150);
    EXPECT_LT(designs, cobyla["designs_in_history"].get<int>() / 4);
    EXPECT_EQ(s["gradient"]["method"], "exact");
    // Every design but those with warnings (infeasible: no derivatives wanted; the axial-force
    // check warns of one on SLSQP's path, its slim struts' own sag 1.2 % off in 2 segments).
    EXPECT_EQ(s["gradient"]["designs_with_exact_derivatives"].get<int>() +
                  s["designs_with_warnings"].get<int>(),
              s["designs_simulated"]);
    EXPECT_LE(s["designs_with_warnings"].get<int>(), 1);
    EXPECT_EQ(s["gradient"]["designs_by_differences"], 0);
    for (const Json& c : s["best"]["constraints"]) {
      EXPECT_TRUE(c["satisfied"].get<bool>()) << c.dump();
      EXPECT_TRUE(c["active"].get<bool>()) << c.dump();  // both bind at this optimum
    }
  }
}

// min_mass_rod started at the upper bound of its diameter: the differences there are one-sided
// inside the bounds (no design beyond them), and no design is simulated twice.
TEST_F(ExactGradients, DifferencesStayInsideTheBoundsAndSimulateNoDesignTwice) {
  Json study = load_json(kSource / "studies/min_mass_rod.json");
  study["study"]["algorithm"] = "LD_SLSQP";
  study["study"]["gradient"] = "fd";
  study["study"]["variables"][0]["initial"] = 0.1;  // the upper bound
  const Json s = run("fd", study);
  ASSERT_EQ(s["status"], "ok") << s["message"];
  const History h = read_history(dir_ / "fd" / "history.csv");
  for (size_t r = 0; r < h.rows.size(); ++r) {
    EXPECT_LE(h.at(r, "d"), 0.1);
    EXPECT_GE(h.at(r, "d"), 0.005);
  }
  EXPECT_EQ(s["designs_simulated"], s["designs_in_history"]);
  const double d = s["best"]["variables"]["d"];
  std::printf("fd from the bound: d = %.9f m in %zu designs\n", d, h.rows.size());
  EXPECT_NEAR(d, 0.048198, 1e-5);

  // The same with exact derivatives: one design per NLopt call.
  study["study"]["gradient"] = "exact";
  const Json e = run("exact", study);
  ASSERT_EQ(e["status"], "ok") << e["message"];
  EXPECT_NEAR(e["best"]["variables"]["d"].get<double>() / d, 1.0, 1e-6);
  EXPECT_LT(e["designs_in_history"].get<int>(), s["designs_in_history"].get<int>() / 2);
}

// A transient's peak has no exact derivative: the designs' gradients come from differences, with
// a warning saying why, and the optimization still ends at its optimum.
TEST_F(ExactGradients, ADesignWithoutExactDerivativesFallsBackToDifferencesWithAWarning) {
  Json study = load_json(kSource / "studies/min_mass_rod.json");
  study["study"]["algorithm"] = "LD_SLSQP";
  study["scene"]["loads"] = Json::parse(
      R"([{"type": "force", "body": "tip", "value": [0, -10, 0], "time": {"type": "step", "at": 0}}])");
  study["analyses"].push_back(Json::parse(
      R"({"type": "transient", "t_end": 0.01, "output_step": 0.001,
          "integrator": {"method": "dirk", "rtol": 1e-8, "atol": 1e-11}})"));
  study["responses"]["peak"] =
      Json::parse(R"({"quantity": "peak_displacement", "body": "tip", "direction": [0, 1, 0]})");
  const Json s = run("fallback", study);
  ASSERT_EQ(s["status"], "ok") << s["message"];
  EXPECT_GT(s["gradient"]["designs_by_differences"].get<int>(), 0);
  EXPECT_NE(s["gradient"]["why_differences"].get<std::string>().find(
                "\"peak\" (the peak of a transient) has no exact derivative"),
            std::string::npos);
  bool warned = false;
  for (const Json& w : s["warnings"])
    warned =
        warned || w.get<std::string>().find("came from central differences") != std::string::npos;
  EXPECT_TRUE(warned) << s["warnings"].dump();
  EXPECT_NEAR(s["best"]["variables"]["d"].get<double>(), 0.048198, 1e-5);
}

// What NLopt sees: variables over their bounds, the objective over its value at the start, each
// constraint over its bound, its given scale, or (bound 0) its magnitude at the first design.
TEST_F(ExactGradients, SummaryGivesTheScaledProblem) {
  Json study = load_json(kSource / "tests/benchmarks/design_loop/table_frame.json");
  study["study"]["algorithm"] = "LD_SLSQP";
  study["study"]["constraints"] = Json::parse(
      R"([{"response": "f1", ">=": 20}, {"response": "dx", "<=": 0.0003, "scale": 1e-4},
          {"response": "dx", ">=": 0}])");
  const Json s = run("scaled", study);
  ASSERT_EQ(s["status"], "ok") << s["message"];
  const Json& scaling = s["scaling"];
  EXPECT_EQ(scaling["variables"][0]["lower"], 0.02);
  EXPECT_EQ(scaling["variables"][0]["upper"], 0.08);
  EXPECT_EQ(scaling["constraints"][0]["scale"], 20.0);
  EXPECT_EQ(scaling["constraints"][1]["scale"], 1e-4);
  // The first design's dx (the start), read from its row.
  const History h = read_history(dir_ / "scaled" / "history.csv");
  EXPECT_EQ(scaling["constraints"][2]["scale"].get<double>(), h.at(0, "dx"));
  EXPECT_EQ(scaling["objective_scale"][0].get<double>(), h.at(0, "mass"));
}

}  // namespace
}  // namespace beamrail
