// A transient that starts at the static equilibrium ("initial": "static") through the real command
// line: a tip mass on a cantilever under gravity stays at its static sag m g L^3 / (3 EI) instead
// of dropping to twice it, and the energy record says what it can: a relative change when the run
// starts with energy, the absolute change when it starts with none.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
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

// A massless 1 m steel cantilever of 10 mm square section along x with a 2 kg tip body under
// gravity (-z): static sag m g L^3 / (3 EI) = 37 mm; the first period 0.39 s (the lowest point of
// a sudden load at 0.19 s).
constexpr double kSag = 2.0 * 9.81 / (3.0 * 2.1e11 * 1e-8 / 12.0);

Json study(const std::string& initial) {
  Json s = Json::parse(R"({
    "name": "sag",
    "scene": {
      "gravity": [0, 0, -9.81],
      "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
      "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
      "bodies": [{"name": "tip", "mass": 2.0, "inertia": [1e-6, 1e-6, 1e-6], "position": [1, 0, 0]}],
      "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
                 "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq"}]
    },
    "analyses": [{"type": "transient", "t_end": 0.25, "output_step": 0.002,
                  "integrator": {"method": "dirk", "rtol": 1e-9, "atol": 1e-12}}]
  })");
  if (!initial.empty()) s["analyses"][0]["initial"] = initial;
  return s;
}

// The tip's z over the run, from timeseries.csv.
std::vector<double> tip_z(const fs::path& path) {
  std::istringstream in(read_text(path));
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.substr(0, 15), "t,tip.x,tip.y,t");
  std::vector<double> z;
  while (std::getline(in, line)) {
    std::vector<double> f;
    std::istringstream fields(line);
    for (std::string x; std::getline(fields, x, ',');) f.push_back(std::stod(x));
    z.push_back(f.at(3));
  }
  return z;
}

class TransientStart : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "beamrail_start_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  Json run_ok(const Json& s, const std::string& name) {
    std::ofstream(dir_ / (name + ".json")) << s.dump(2);
    const ProcessResult r = testing::run_process(
        BEAMRAIL_EXECUTABLE, {"run", name + ".json", "-o", name, "--quiet"}, dir_);
    EXPECT_TRUE(r.exited && r.status == 0) << r.how << "\n" << r.err;
    return Json::parse(read_text(dir_ / name / "summary.json"));
  }
  fs::path dir_;
};

TEST_F(TransientStart, FromTheStaticEquilibriumTheTipStaysAtItsSag) {
  const Json at_rest = run_ok(study("static"), "static");
  const Json dropped = run_ok(study(""), "scene");
  const std::vector<double> still = tip_z(dir_ / "static/timeseries.csv");
  const std::vector<double> falling = tip_z(dir_ / "scene/timeseries.csv");
  double still_worst = 0.0, lowest = 0.0;
  for (double z : still) still_worst = std::max(still_worst, std::abs(z + kSag));
  for (double z : falling) lowest = std::min(lowest, z);
  std::printf(
      "static sag %.6e m; from the equilibrium: start %.9e m, largest departure %.2e m; "
      "from the scene's state: lowest %.6e m (%.4f sags)\n",
      kSag, still.front(), still_worst, lowest, -lowest / kSag);
  // The equilibrium is the geometrically nonlinear one; for this single beam it is the linear
  // sag to 3e-7 (measured).
  EXPECT_NEAR(-still.front() / kSag, 1.0, 1e-5);
  EXPECT_LT(still_worst, 1e-6 * kSag);
  // A load applied at once overshoots to twice the static deflection.
  EXPECT_NEAR(-lowest / kSag, 2.0, 2e-3);
  EXPECT_EQ(at_rest["analyses"][0]["initial"], "static");
  EXPECT_EQ(at_rest["analyses"][0]["initial_equilibrium"]["converged"], true);
  EXPECT_EQ(dropped["analyses"][0]["initial"], "scene");
  // Gravity's energy is relative to the origin: E0 = -m g z_tip != 0; at rest it stays.
  EXPECT_LT(at_rest["analyses"][0]["energy_max_relative_change"].get<double>(), 1e-9);
}

// A run that starts with no energy (at rest, no gravity) under a step load: no relative change
// (it would divide by zero and read 1.0), the absolute change instead: the work of the load,
// P times the tip's travel.
TEST_F(TransientStart, ARunStartingWithoutEnergyReportsTheAbsoluteChange) {
  Json s = study("");
  s["scene"].erase("gravity");
  s["scene"]["loads"] = {{{"type", "force"},
                          {"body", "tip"},
                          {"value", {0, 0, -19.62}},
                          {"time", {{"type", "step"}}}}};
  const Json summary = run_ok(s, "step");
  const Json& a = summary["analyses"][0];
  EXPECT_EQ(a["energy_initial"].get<double>(), 0.0);
  EXPECT_TRUE(a["energy_max_relative_change"].is_null()) << a.dump(2);
  // Kinetic + elastic energy reach at most the load's work P x 2 sag at the lowest point.
  const double work = 19.62 * 2.0 * kSag;
  std::printf("energy_max_change %.6e J, load work to the lowest point %.6e J\n",
              a["energy_max_change"].get<double>(), work);
  EXPECT_NEAR(a["energy_max_change"].get<double>() / work, 1.0, 5e-3);
}

// A study's transient without a method runs "auto" and says what it chose; "max_frequency_hz":
// "output" is half the output rate (here 250 Hz: the first mode, 2.6 Hz, is integrated, the tip's
// fast rotary mode is quasi-static), "auto" the band chosen for rtol (the two bending modes, the
// rotary ones quasi-static), which summary.json reports as it reports a given one; and the tip
// still overshoots to twice its static sag.
TEST_F(TransientStart, TheDefaultMethodIsAutoAndTheBandCanFollowTheOutput) {
  for (const std::string band : {"", "output", "auto"}) {
    Json s = study("");
    s["analyses"][0]["integrator"] = {{"rtol", 1e-8}, {"atol", 1e-11}};
    if (!band.empty()) s["analyses"][0]["max_frequency_hz"] = band;
    const std::string name = band.empty() ? "every_mode" : band;
    const Json summary = run_ok(s, name);
    const Json& a = summary["analyses"][0];
    EXPECT_EQ(a["integrator"], "auto");
    EXPECT_EQ(a["method"], "modal");
    const std::string reason = a["method_reason"].get<std::string>();
    EXPECT_NE(reason.find("1 free body"), std::string::npos);
    // The tip turns 0.11 rad: relinearized as it goes (small scene: every 0.02 rad).
    EXPECT_EQ(a["phase_count"].get<size_t>(), a["phases"].size());
    for (const Json& p : a["phases"]) EXPECT_EQ(p["method"], "modal") << p.dump();
    if (band == "output") {
      EXPECT_DOUBLE_EQ(a["max_frequency_hz"].get<double>(), 0.5 / 0.002);
    } else if (band == "auto") {
      // The band the reason names, to all its digits; every phase chose one as low.
      const size_t at = reason.find("band ");
      ASSERT_NE(at, std::string::npos) << reason;
      const double chosen = std::stod(reason.substr(at + 5));
      std::printf("chosen band %.6f Hz: %s\n", chosen, reason.c_str());
      EXPECT_GE(a["max_frequency_hz"].get<double>(), chosen);
      EXPECT_LT(a["max_frequency_hz"].get<double>(), 1.01 * chosen);
      EXPECT_GT(chosen, 2.5);  // the first bending mode (2.6 Hz) is integrated
      EXPECT_LT(chosen, 250.0);
    } else {
      EXPECT_FALSE(a.contains("max_frequency_hz"));
    }
    double lowest = 0.0;
    for (double z : tip_z(dir_ / name / "timeseries.csv")) lowest = std::min(lowest, z);
    std::printf("%s: lowest %.6f sags, %d steps\n", name.c_str(), -lowest / kSag,
                a["steps"].get<int>());
    EXPECT_NEAR(-lowest / kSag, 2.0, 2e-3);
  }
}

}  // namespace
}  // namespace beamrail
