// Named analyses and load cases through the real command line: each analysis applies the loads
// of its case (and those without one), responses read the analysis they name, tables of several
// analyses of one type do not overwrite each other, and every ambiguous or unknown reference is
// bad input with its JSON pointer.
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

namespace beamrail {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using testing::ProcessResult;
using testing::read_text;

constexpr double kE = 2.1e11, kSide = 0.01, kLength = 1.0;
constexpr double kI = kSide * kSide * kSide * kSide / 12.0;
constexpr double kArea = kSide * kSide;

// A massless 1 m steel cantilever of 10 mm square section with a tip body: a 0.01 N side load in
// case "side" (along y), a 0.02 N load in case "down" (along -z), a 100 N axial pull without a
// case (every analysis applies it).
Json cantilever_study() {
  return Json::parse(R"({
    "name": "cases",
    "scene": {
      "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
      "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
      "bodies": [{"name": "tip", "mass": 1.0, "inertia": [1e-4, 1e-4, 1e-4], "position": [1, 0, 0]}],
      "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
                 "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq"}],
      "loads": [
        {"type": "force", "body": "tip", "value": [0, 0.01, 0], "case": "side"},
        {"type": "force", "body": "tip", "value": [0, 0, -0.02], "case": "down"},
        {"type": "force", "body": "tip", "value": [100, 0, 0]}
      ]
    },
    "analyses": [
      {"type": "static", "name": "side", "load_case": "side"},
      {"type": "static", "name": "down", "load_case": "down"}
    ],
    "responses": {
      "side_dy": {"quantity": "displacement", "body": "tip", "direction": [0, 1, 0], "analysis": "side"},
      "side_dz": {"quantity": "displacement", "body": "tip", "direction": [0, 0, 1], "analysis": "side"},
      "down_dy": {"quantity": "displacement", "body": "tip", "direction": [0, 1, 0], "analysis": "down"},
      "down_dz": {"quantity": "displacement", "body": "tip", "direction": [0, 0, 1], "analysis": "down"},
      "down_dx": {"quantity": "displacement", "body": "tip", "direction": [1, 0, 0], "analysis": "down"}
    }
  })");
}

// The row of `body` in a static_displacements table: dx, dy, dz, rx, ry, rz.
std::vector<double> displacement_row(const fs::path& path, const std::string& body) {
  std::istringstream in(read_text(path));
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "body,dx,dy,dz,rx,ry,rz");
  while (std::getline(in, line)) {
    if (line.rfind(body + ",", 0) != 0) continue;
    std::vector<double> out;
    std::istringstream fields(line.substr(body.size() + 1));
    for (std::string f; std::getline(fields, f, ',');) out.push_back(std::stod(f));
    return out;
  }
  ADD_FAILURE() << "no row for " << body << " in " << path;
  return std::vector<double>(6, NAN);
}

class LoadCases : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "beamrail_cases_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  ProcessResult run(const Json& study, const std::string& name, const std::string& command) {
    std::ofstream(dir_ / (name + ".json")) << study.dump(2);
    std::vector<std::string> args{command, name + ".json"};
    if (command == "run") args.insert(args.end(), {"-o", name, "--quiet"});
    return testing::run_process(BEAMRAIL_EXECUTABLE, args, dir_);
  }
  // Runs the study into dir_/name; it must succeed. Returns summary.json.
  Json run_ok(const Json& study, const std::string& name) {
    const ProcessResult r = run(study, name, "run");
    EXPECT_TRUE(r.exited && r.status == 0) << r.how << "\n" << r.err;
    return Json::parse(read_text(dir_ / name / "summary.json"));
  }
  // `beamrail check` must refuse the study with exit status 2 and this message at this pointer.
  void expect_refused(const Json& study, const std::string& pointer, const std::string& message) {
    const ProcessResult r = run(study, "bad", "check");
    EXPECT_TRUE(r.exited && r.status == 2) << r.how << "\n" << r.err;
    EXPECT_NE(r.err.find("bad.json:" + pointer + ": "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
  }
  fs::path dir_;
};

// Each static analysis applies its case's load and the load without a case; before, both
// responses came from the first analysis (a silent wrong answer).
TEST_F(LoadCases, EachStaticAnalysisAppliesItsCaseAndWritesItsOwnTables) {
  const Json summary = run_ok(cantilever_study(), "out");
  ASSERT_EQ(summary["status"], "ok") << summary.dump(2);
  const Json& r = summary["responses"];
  const double bending = kLength * kLength * kLength / (3.0 * kE * kI);  // per newton
  const double axial = 100.0 * kLength / (kE * kArea);
  // Tension of 100 N stiffens the bending by a relative ~ P L^2 / (EI) x 2/5 = 2e-4 (2nd order).
  EXPECT_NEAR(r["side_dy"].get<double>() / (0.01 * bending), 1.0, 1e-3);
  EXPECT_NEAR(r["down_dz"].get<double>() / (-0.02 * bending), 1.0, 1e-3);
  EXPECT_EQ(r["side_dz"].get<double>(), 0.0);
  EXPECT_EQ(r["down_dy"].get<double>(), 0.0);
  EXPECT_NEAR(r["down_dx"].get<double>() / axial, 1.0, 1e-6);
  // The tables: "<name>.<table>", each with its own analysis's displacements.
  const std::vector<double> side =
      displacement_row(dir_ / "out/side.static_displacements.csv", "tip");
  const std::vector<double> down =
      displacement_row(dir_ / "out/down.static_displacements.csv", "tip");
  EXPECT_EQ(side[1], r["side_dy"].get<double>());
  EXPECT_EQ(down[2], r["down_dz"].get<double>());
  EXPECT_NEAR(side[0] / axial, 1.0, 1e-6);  // the axial pull without a case: in both
  EXPECT_FALSE(fs::exists(dir_ / "out/static_displacements.csv"));
  ASSERT_EQ(summary["analyses"].size(), 2u);
  EXPECT_EQ(summary["analyses"][0]["name"], "side");
  EXPECT_EQ(summary["analyses"][0]["load_case"], "side");
  EXPECT_EQ(summary["analyses"][1]["tables"],
            Json::array({"down.static_displacements.csv", "down.element_forces.csv"}));
}

// Unnamed analyses of one type are numbered; a single one keeps the plain table names.
TEST_F(LoadCases, DefaultNamesNumberRepeatedTypes) {
  Json study = cantilever_study();
  for (Json& a : study["analyses"]) a.erase("name");
  study["analyses"].push_back({{"type", "modal"}, {"modes", 2}, {"load_case", "side"}});
  study["responses"] = {{"dy",
                         {{"quantity", "displacement"},
                          {"body", "tip"},
                          {"direction", {0, 1, 0}},
                          {"analysis", "static_1"}}},
                        {"dz",
                         {{"quantity", "displacement"},
                          {"body", "tip"},
                          {"direction", {0, 0, 1}},
                          {"analysis", "static_2"}}}};
  const Json summary = run_ok(study, "out");
  ASSERT_EQ(summary["status"], "ok") << summary.dump(2);
  EXPECT_EQ(summary["analyses"][0]["name"], "static_1");
  EXPECT_EQ(summary["analyses"][1]["name"], "static_2");
  EXPECT_EQ(summary["analyses"][2]["name"], "modal");
  EXPECT_TRUE(fs::exists(dir_ / "out/static_1.static_displacements.csv"));
  EXPECT_TRUE(fs::exists(dir_ / "out/static_2.element_forces.csv"));
  EXPECT_TRUE(fs::exists(dir_ / "out/modes.csv"));
  EXPECT_NE(summary["responses"]["dy"].get<double>(), 0.0);
  EXPECT_NE(summary["responses"]["dz"].get<double>(), 0.0);
}

// A modal analysis of a case is linearized about that case's equilibrium: the same frequencies
// as a study whose scene has only those loads, and not those of the scene without them.
TEST_F(LoadCases, ModalAnalysisOfACaseEqualsTheSceneWithOnlyItsLoads) {
  Json study = cantilever_study();
  study["scene"]["materials"]["steel"]["density"] = 7850;
  study["scene"]["beams"][0]["segments"] = 4;
  study["scene"]["loads"][1]["value"] = {-300, 0, 0};  // 0.7 of the Euler load: f1 drops
  study["analyses"] = {{{"type", "modal"}, {"modes", 3}, {"load_case", "down"}}};
  study["responses"] = {{"f1", {{"quantity", "frequency"}, {"mode", 1}}},
                        {"f3", {{"quantity", "frequency"}, {"mode", 3}}}};
  const Json with_cases = run_ok(study, "cases");
  Json alone = study;
  alone["scene"]["loads"] = {study["scene"]["loads"][1], study["scene"]["loads"][2]};
  alone["scene"]["loads"][0].erase("case");
  alone["analyses"][0].erase("load_case");
  const Json single = run_ok(alone, "alone");
  ASSERT_EQ(with_cases["status"], "ok") << with_cases.dump(2);
  for (const char* f : {"f1", "f3"})
    EXPECT_EQ(with_cases["responses"][f], single["responses"][f]) << f;
  Json other = study;
  other["analyses"][0]["load_case"] = "side";
  const Json side = run_ok(other, "side");
  const double ratio =
      side["responses"]["f1"].get<double>() / single["responses"]["f1"].get<double>();
  std::printf("f1 under the axial case / under the side case: %.6f\n", 1.0 / ratio);
  EXPECT_GT(ratio, 1.2);
}

// A transient of a case applies its loads only: its time series equals that of the scene with
// only those loads.
TEST_F(LoadCases, TransientOfACaseEqualsTheSceneWithOnlyItsLoads) {
  Json study = cantilever_study();
  study["analyses"] = {{{"type", "transient"},
                        {"t_end", 0.01},
                        {"output_step", 0.001},
                        {"load_case", "side"},
                        {"name", "shake"}}};
  study["responses"] = Json::object();
  run_ok(study, "cases");
  Json alone = study;
  alone["scene"]["loads"] = {study["scene"]["loads"][0], study["scene"]["loads"][2]};
  alone["scene"]["loads"][0].erase("case");
  alone["analyses"][0].erase("load_case");
  alone["analyses"][0].erase("name");
  run_ok(alone, "alone");
  const std::string a = read_text(dir_ / "cases/shake.timeseries.csv");
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, read_text(dir_ / "alone/timeseries.csv"));
}

TEST_F(LoadCases, AmbiguousOrUnknownReferencesAreBadInput) {
  Json s = cantilever_study();
  s["responses"]["side_dy"].erase("analysis");
  expect_refused(s, "/responses/side_dy/analysis",
                 "the study has 2 static analyses (\"side\", \"down\"): name the one");
  s = cantilever_study();
  s["responses"]["side_dy"]["analysis"] = "sideways";
  expect_refused(s, "/responses/side_dy/analysis", "unknown analysis \"sideways\"");
  s = cantilever_study();
  s["analyses"].push_back({{"type", "modal"}, {"name", "vib"}});
  s["responses"]["side_dy"]["analysis"] = "vib";
  expect_refused(s, "/responses/side_dy/analysis",
                 "analysis \"vib\" is a modal analysis; \"displacement\" needs a static analysis");
  s = cantilever_study();
  s["analyses"][0]["load_case"] = "sidee";
  expect_refused(s, "/analyses/0/load_case",
                 "no load has the case \"sidee\" (the loads' cases: \"side\", \"down\")");
  s = cantilever_study();
  s["analyses"][1]["name"] = "side";
  expect_refused(s, "/analyses/1/name", "analysis name \"side\" is used twice");
  s = cantilever_study();
  s["analyses"][1]["name"] = "../up";
  expect_refused(s, "/analyses/1/name", "must be 1 to 64 letters");
  s = cantilever_study();
  s["scene"]["loads"][0]["case"] = "";
  expect_refused(s, "/scene/loads/0/case", "must not be empty");
  s = cantilever_study();
  s["responses"]["m"] = {{"quantity", "mass"}, {"analysis", "side"}};
  expect_refused(s, "/responses/m/analysis", "unknown key \"analysis\"");
}

}  // namespace
}  // namespace beamrail
