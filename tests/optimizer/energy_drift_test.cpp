// A run that cannot be trusted says so: through the real command line, a transient of a scene
// that keeps its energy warns when its energy drifts more than 10 rtol, and a verification rerun
// farther than 10 rtol from the run warns. The scene is a free pair of bodies on a stiff steel
// rod, spinning (found by an adversarial review: auto at rtol 1e-4 was 30 rtol off in 3 s, status
// ok, without a warning; auto now follows it in a turning frame and is within rtol, while dirk
// at rtol 1e-3 with atol 1e-3 stands for a run that is not: 13 rtol off. dirk at rtol 1e-4 stood
// for it until 2026-11-30: with atol 3e-8 127 rtol off through the stage derivatives it deduced
// (1.1 rtol since 2026-11-29), with atol 1e-4 19 rtol off through interpolated outputs (1.9 rtol
// since its steps end on them, integrators.cpp); the independent
// reference is the explicit Verner 8(7) table at rtol 1e-11, the errors the largest body-centre
// distance over the largest motion.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/support/study_runs.hpp"

namespace beamrail {
namespace {

using Json = nlohmann::json;
using testing::load_json;
using testing::read_table;
using testing::Table;

Json spinning_pair(const Json& integrator, double t_end = 3.0) {
  Json s = Json::parse(R"({
    "name": "spinning_pair",
    "scene": {
      "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
      "sections": {"rod": {"shape": "circle", "diameter": 0.02}},
      "bodies": [
        {"name": "a", "mass": 1.0, "inertia": [0.002, 0.01, 0.012], "position": [0, 0, 0],
         "angular_velocity": [0.1, 0.1, 1.5], "velocity": [0, -0.225, 0.02]},
        {"name": "b", "mass": 1.0, "inertia": [0.003, 0.002, 0.004], "position": [0.3, 0, 0],
         "angular_velocity": [0.05, 0.1, 1.5], "velocity": [0, 0.225, 0]}],
      "beams": [{"name": "ab", "body1": "a", "body2": "b", "point1": [0, 0, 0],
                 "point2": [0.3, 0, 0], "point3": [0, 1, 0], "material": "steel",
                 "section": "rod"}]
    },
    "analyses": [{"type": "transient", "name": "spin", "t_end": 3.0, "output_step": 0.05}]
  })");
  s["analyses"][0]["integrator"] = integrator;
  s["analyses"][0]["t_end"] = t_end;
  return s;
}

// The largest distance between the two runs' body centres over the largest distance a centre
// moved in the reference (timeseries.csv: t, then x, y, z, q0..q3 per body, then energy).
double centre_error(const Table& run, const Table& reference) {
  EXPECT_EQ(run.rows.size(), reference.rows.size());
  double error = 0.0, motion = 0.0;
  for (const std::string body : {"a", "b"})
    for (size_t i = 0; i < std::min(run.rows.size(), reference.rows.size()); ++i) {
      double d2 = 0.0, m2 = 0.0;
      for (const std::string c : {".x", ".y", ".z"}) {
        const double r = std::stod(reference.at(i, body + c));
        d2 += std::pow(std::stod(run.at(i, body + c)) - r, 2);
        m2 += std::pow(r - std::stod(reference.at(0, body + c)), 2);
      }
      error = std::max(error, std::sqrt(d2));
      motion = std::max(motion, std::sqrt(m2));
    }
  return error / motion;
}

std::vector<std::string> warnings_of(const Json& summary) {
  std::vector<std::string> out;
  if (summary.contains("warnings"))
    for (const Json& w : summary["warnings"]) out.push_back(w.get<std::string>());
  return out;
}

bool has(const std::vector<std::string>& warnings, const std::string& text) {
  return std::any_of(warnings.begin(), warnings.end(),
                     [&](const std::string& w) { return w.find(text) != std::string::npos; });
}

// The figure written before `unit` in the warning that holds `text` (its last number before it).
double figure_before(const std::vector<std::string>& warnings, const std::string& text,
                     const std::string& unit) {
  for (const std::string& w : warnings) {
    if (w.find(text) == std::string::npos) continue;
    const size_t end = w.find(unit, w.find(text));
    const size_t begin = end == std::string::npos ? end : w.find_last_of("( ", end - 1);
    if (end == std::string::npos || begin == std::string::npos) return NAN;
    return std::stod(w.substr(begin + 1, end - begin - 1));
  }
  return NAN;
}

class EnergyDrift : public testing::StudyRuns {
 protected:
  // Runs the pair with `integrator` (and `verify`); its summary, and its error against the
  // reference.
  Json run_pair(const std::string& name, const Json& integrator, bool verify, double* error,
                double t_end = 3.0, bool refine = true) {
    Json s = spinning_pair(integrator, t_end);
    if (verify) s["analyses"][0]["verify"] = true;
    if (!refine) s["analyses"][0]["refine"] = false;
    run_ok(write_study(name + ".json", s), name);
    if (reference_.rows.empty()) {
      run_ok(
          write_study(
              "reference.json",
              spinning_pair(
                  {{"method", "erk"}, {"table", "VERNER_8_5_6"}, {"rtol", 1e-11}, {"atol", 3e-15}},
                  t_end)),
          "reference");
      reference_ = read_table(dir_ / "reference/spin.timeseries.csv");
    }
    *error = centre_error(read_table(dir_ / name / "spin.timeseries.csv"), reference_);
    return load_json(dir_ / name / "summary.json");
  }
  Table reference_;
};

TEST_F(EnergyDrift, ASpinningPairWarnsWhereItsEnergyAndMotionAreOffAndNotWhereTheyAreNot) {
  double off_error = 0.0, loose_error = 0.0, tight_error = 0.0;
  const Json off =
      run_pair("off", {{"method", "dirk"}, {"rtol", 1e-3}, {"atol", 1e-3}}, false, &off_error);
  const Json loose =
      run_pair("loose", {{"method", "auto"}, {"rtol", 1e-4}, {"atol", 3e-8}}, false, &loose_error);
  const Json tight =
      run_pair("tight", {{"method", "auto"}, {"rtol", 1e-8}, {"atol", 3e-12}}, false, &tight_error);
  const std::vector<std::string> warned = warnings_of(off);
  const double drift = figure_before(warned, "the energy changed by", " rtol)");
  std::printf(
      "dirk, rtol 1e-3: motion %.2e (%.0f rtol), energy drift %.0f rtol; auto, rtol 1e-4: %.2e "
      "(%.3f rtol); rtol 1e-8: %.2e (%.3f rtol)\n",
      off_error, off_error / 1e-3, drift, loose_error, loose_error / 1e-4, tight_error,
      tight_error / 1e-8);
  // The warning is right: the motion is more than 10 rtol off (13 measured) ...
  EXPECT_EQ(off["status"], "ok");
  EXPECT_GT(off_error, 10 * 1e-3);
  EXPECT_TRUE(has(warned, "transient \"spin\": the energy changed by")) << off.dump(2);
  EXPECT_GT(drift, 10.0);
  // ... and the drift it quotes is the summary's, over the largest kinetic + elastic energy: the
  // run gains energy (7.0 % at most, 6.5 % at the end), so the largest is the initial energy,
  // all kinetic, times 1 + the summary's change.
  const Json& a = off["analyses"][0];
  const double relative = a["energy_max_relative_change"].get<double>();
  EXPECT_GT(a["energy_final"].get<double>(), a["energy_initial"].get<double>());
  const double of_largest = relative / (1.0 + relative) / 1e-3;
  EXPECT_NEAR(drift, of_largest, 0.02 * of_largest);
  // auto at rtol 1e-4 and 1e-8 is within its tolerance and says nothing.
  EXPECT_LT(loose_error, 10 * 1e-4);
  EXPECT_TRUE(warnings_of(loose).empty()) << loose.dump(2);
  EXPECT_LT(tight_error, 10 * 1e-8);
  EXPECT_TRUE(warnings_of(tight).empty()) << tight.dump(2);
}

TEST_F(EnergyDrift, AVerificationFartherThanTenRtolWarnsWithItsFigure) {
  // Over 6 s the same run drifts to 55 rtol of the motion, beyond 10 times rtol + atol / motion
  // (its tolerance, 0.3 m of motion: 43 rtol), which the 3 s run (13 rtol) is not.
  double error = 0.0;
  const Json s = run_pair("verified", {{"method", "dirk"}, {"rtol", 1e-3}, {"atol", 1e-3}}, true,
                          &error, 6.0, false);
  const Json& v = s["analyses"][0]["verification"];
  const std::vector<std::string> warned = warnings_of(s);
  const double quoted = figure_before(warned,
                                      "the verification rerun at rtol / 10 moved the body "
                                      "centres by",
                                      " rtol)");
  std::printf("verification %.3e, quoted %.0f rtol; against the reference %.3e\n",
              v["error"].get<double>(), quoted, error);
  ASSERT_TRUE(has(warned, "the run is not within its tolerance")) << s.dump(2);
  EXPECT_NEAR(quoted, v["error"].get<double>() / 1e-3, 0.02 * quoted);
  // The rerun's distance is an estimate of the run's own error (within a factor of 2 here).
  EXPECT_GT(v["error"].get<double>(), 0.5 * error);
  EXPECT_LT(v["error"].get<double>(), 2.0 * error);

  // By default ("refine") such a run is run again at its rerun's tolerances, whose results
  // replace it: within 10 times the tolerance asked against the reference, and no warning of it.
  double refined_error = 0.0;
  const Json r = run_pair("refined", {{"method", "dirk"}, {"rtol", 1e-3}, {"atol", 1e-3}}, true,
                          &refined_error, 6.0);
  const Json& a = r["analyses"][0];
  ASSERT_TRUE(a.contains("refinement")) << r.dump(2);
  std::printf(
      "refined at rtol %.0e: %.3e against the reference (%.1f rtol asked), its "
      "verification %.3e; %ld steps against the first run's %ld\n",
      a["refinement"]["rtol"].get<double>(), refined_error, refined_error / 1e-3,
      a["verification"]["error"].get<double>(), a["steps"].get<long>(),
      a["refinement"]["first_run"]["steps"].get<long>());
  EXPECT_DOUBLE_EQ(a["refinement"]["rtol"].get<double>(), 1e-4);
  EXPECT_EQ(a["refinement"]["first_run"]["error"].get<double>(), v["error"].get<double>());
  EXPECT_DOUBLE_EQ(a["verification"]["rtol"].get<double>(), 1e-5);
  EXPECT_LT(refined_error, 10 * (1e-3 + 1e-3 / 0.3));
  EXPECT_LT(refined_error, error / 5.0);
  EXPECT_FALSE(has(warnings_of(r), "not within")) << r.dump(2);
}

// Where the energy need not be kept (a load does work, a beam is damped, the paper's law) the
// drift is no sign of error and the run does not warn of it.
TEST_F(EnergyDrift, ScenesThatDoNotKeepTheirEnergyDoNotWarnOfIt) {
  Json loaded = spinning_pair({{"method", "auto"}, {"rtol", 1e-4}, {"atol", 3e-8}});
  loaded["scene"]["loads"] = {{{"type", "force"}, {"body", "a"}, {"value", {0, 0, 1e-3}}}};
  Json damped = spinning_pair({{"method", "auto"}, {"rtol", 1e-4}, {"atol", 3e-8}});
  damped["scene"]["beams"][0]["damping"] = 1e-7;
  Json paper = spinning_pair({{"method", "auto"}, {"rtol", 1e-4}, {"atol", 3e-8}});
  paper["scene"]["beams"][0]["formulation"] = "paper";
  for (const auto& [name, study] :
       {std::pair{"loaded", loaded}, {"damped", damped}, {"paper", paper}}) {
    run_ok(write_study(std::string(name) + ".json", study), name);
    const Json summary = load_json(dir_ / name / "summary.json");
    const double relative = summary["analyses"][0]["energy_max_relative_change"].get<double>();
    std::printf("%s: energy changed by %.2e\n", name, relative);
    EXPECT_FALSE(has(warnings_of(summary), "the energy changed by")) << summary.dump(2);
  }
}

// A cantilever in 20 segments under gravity started at its static equilibrium and nudged by a
// 1e-8 N step moves by 2e-12 m, where rounding is a part of it: its rerun is 3.2e-4 of that away
// (315 rtol; 0.012 while dirk's outputs were interpolated, until 2026-11-30). A review found verify
// warned of such a run (then moved by rounding only, 3.6e-12 m, through dirk's deduced stage
// derivatives) as 1.3 million rtol. Within atol, it is no sign of error: no warning. The energy
// does not warn either.
TEST_F(EnergyDrift, MotionWithinAtolDoesNotWarn) {
  const Json s = Json::parse(R"({
    "name": "at_rest",
    "scene": {
      "gravity": [0, 0, -9.81],
      "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
      "sections": {"rod": {"shape": "circle", "diameter": 0.02}},
      "bodies": [{"name": "tip", "mass": 1.0, "inertia": [1e-4, 1e-4, 1e-4], "position": [1, 0, 0]}],
      "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
                 "segments": 20, "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel",
                 "section": "rod"}],
      "loads": [{"type": "force", "body": "tip", "value": [0, 1e-8, 0],
                 "time": {"type": "step", "at": 0.001}}]
    },
    "analyses": [{"type": "transient", "name": "ring", "t_end": 0.05, "output_step": 0.0005,
                  "integrator": {"method": "dirk"}, "verify": true, "initial": "static"}]
  })");
  run_ok(write_study("at_rest.json", s), "at_rest");
  const Json summary = load_json(dir_ / "at_rest/summary.json");
  const Json& v = summary["analyses"][0]["verification"];
  std::printf("verification: %s\n", v.dump().c_str());
  // The rerun is far beyond 10 rtol (1e-5) of the motion ...
  ASSERT_TRUE(v["error"].is_number()) << summary.dump(2);
  EXPECT_GT(v["error"].get<double>(), 1e-4);
  // ... and well within atol: no warning of it, nor of the energy.
  EXPECT_FALSE(has(warnings_of(summary), "the verification rerun")) << summary.dump(2);
  EXPECT_FALSE(has(warnings_of(summary), "the energy changed by")) << summary.dump(2);
}

}  // namespace
}  // namespace beamrail
