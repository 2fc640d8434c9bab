// Driven bodies through the beamrail command: a peak_displacement seen from a spinning hub
// ("relative_to") against the closed form of a spun-up shaft (as in
// tests/core/analysis/prescribed_motion_test.cpp), and the spin-up study (studies/spin_up.json)
// by two integrators.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>

#include "tests/support/run_process.hpp"

namespace beamrail {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
constexpr double kPi = std::numbers::pi;

Json run_study(const fs::path& dir, const Json& study) {
  fs::create_directories(dir);
  std::ofstream(dir / "study.json") << study.dump(2);
  const testing::ProcessResult r =
      testing::run_process(BEAMRAIL_EXECUTABLE, {"run", "study.json", "-o", "out"}, dir);
  EXPECT_TRUE(r.exited && r.status == 0) << r.how << "\n" << r.err;
  return Json::parse(testing::read_text(dir / "out" / "summary.json"));
}

// The hub spun up about x to w_s = 10 rad/s over T = 1 s by the smooth ramp, then held: its angle
// theta(t) = w_s T (s^2 / 2 + (cos 2 pi s - 1) / (4 pi^2)), s = t / T, then w_s (t - T / 2). The
// disc on the shaft lags by psi(t) (the closed form of the core test). A point of the disc 0.1 m
// off the axis (along y at the start) is, seen from the hub, turned by psi: its displacement along
// z is 0.1 sin psi; in global axes it is 0.1 sin(theta + psi).
TEST(PrescribedMotionStudy, PeakSeenFromTheSpinningHubIsTheShaftsTwist) {
  const double ws = 10.0, big_t = 1.0, j = 0.02, w = 30.0, nu = 2 * kPi / big_t, r = 0.1;
  const double g = 8.0769e10, ix = w * w * j / g;
  const Json study = {
      {"name", "spun_shaft"},
      {"scene",
       {{"materials", {{"steel", {{"E", 2.1e11}, {"G", g}}}}},
        {"sections",
         {{"shaft", {{"shape", "custom"}, {"S", 1e-4}, {"Ix", ix}, {"Iy", 1e-8}, {"Iz", 1e-8}}}}},
        {"bodies",
         {{{"name", "hub"},
           {"position", {0, 0, 0}},
           {"motion",
            {{"angular_velocity", {ws, 0, 0}},
             {"angular_velocity_time", {{"type", "smooth_ramp"}, {"from", 0}, {"to", big_t}}}}}},
          {{"name", "disc"}, {"mass", 1.0}, {"inertia", {j, j, j}}, {"position", {1, 0, 0}}}}},
        {"beams",
         {{{"name", "shaft"},
           {"body1", "hub"},
           {"body2", "disc"},
           {"point1", {0, 0, 0}},
           {"point2", {1, 0, 0}},
           {"point3", {0, 1, 0}},
           {"material", "steel"},
           {"section", "shaft"}}}}}},
      {"analyses",
       {{{"type", "transient"},
         {"t_end", 2.0},
         {"output_step", 0.01},
         {"integrator", {{"method", "bdf"}, {"rtol", 1e-10}, {"atol", 1e-14}}}}}},
      {"responses",
       {{"seen_from_hub",
         {{"quantity", "peak_displacement"},
          {"body", "disc"},
          {"point", {1, r, 0}},
          {"direction", {0, 0, 1}},
          {"relative_to", "hub"}}},
        {"global",
         {{"quantity", "peak_displacement"},
          {"body", "disc"},
          {"point", {1, r, 0}},
          {"direction", {0, 0, 1}}}}}}};
  const fs::path dir = fs::temp_directory_path() / "beamrail_prescribed_motion_study";
  fs::remove_all(dir);
  const Json summary = run_study(dir, study);
  const double a = ws / big_t, c = a * (1 / (w * w) - 1 / (w * w - nu * nu));
  const auto during = [&](double t) {
    return -a * (1 / (w * w) - std::cos(nu * t) / (w * w - nu * nu)) + c * std::cos(w * t);
  };
  const auto during_rate = [&](double t) {
    return -a * nu * std::sin(nu * t) / (w * w - nu * nu) - c * w * std::sin(w * t);
  };
  double seen = 0.0, global = 0.0;
  for (int k = 0; k <= 200; ++k) {
    const double t = 0.01 * k, s = std::min(t / big_t, 1.0);
    const double psi = t <= big_t ? during(t)
                                  : during(big_t) * std::cos(w * (t - big_t)) +
                                        during_rate(big_t) / w * std::sin(w * (t - big_t));
    const double theta =
        t <= big_t ? ws * big_t * (0.5 * s * s + (std::cos(2 * kPi * s) - 1) / (4 * kPi * kPi))
                   : ws * (t - big_t / 2);
    seen = std::max(seen, std::abs(r * std::sin(psi)));
    global = std::max(global, std::abs(r * std::sin(theta + psi)));
  }
  const Json& responses = summary["responses"];
  std::printf("seen from the hub: %.10e m (closed form %.10e); global: %.10e m (%.10e)\n",
              responses["seen_from_hub"].get<double>(), seen, responses["global"].get<double>(),
              global);
  EXPECT_NEAR(responses["seen_from_hub"].get<double>(), seen, 1e-7 * seen);
  EXPECT_NEAR(responses["global"].get<double>(), global, 1e-7 * global);
  EXPECT_GT(global, 0.99 * r);  // the hub's turns, which relative_to removes
  fs::remove_all(dir);
}

// The spin-up study: the auto method runs an implicit Runge-Kutta method (DIRK) and says why; its
// tip deflections seen from the hub agree with those of another pair (ESDIRK437) at a hundred
// times tighter tolerance.
TEST(PrescribedMotionStudy, SpinUpStudyAgreesBetweenTwoMethods) {
  const fs::path dir = fs::temp_directory_path() / "beamrail_spin_up_study";
  fs::remove_all(dir);
  Json study = Json::parse(testing::read_text(fs::path(BEAMRAIL_STUDIES_DIR) / "spin_up.json"));
  const Json automatic = run_study(dir / "auto", study);
  const Json& phase = automatic["analyses"][0]["phases"][0];
  EXPECT_EQ(phase["method"], "dirk");
  EXPECT_NE(phase["reason"].get<std::string>().find("body \"hub\" moves as prescribed"),
            std::string::npos)
      << phase.dump();
  study["analyses"][0]["integrator"] = {
      {"method", "dirk"}, {"table", "ARK437L2SA_DIRK_7_3_4"}, {"rtol", 1e-9}, {"atol", 1e-12}};
  const Json dirk = run_study(dir / "dirk", study);
  for (const char* name : {"tip_lag", "tip_along"}) {
    const double x = automatic["responses"][name].get<double>(),
                 y = dirk["responses"][name].get<double>();
    std::printf("%s: auto (DIRK 8-4-5, rtol 1e-7) %.8e m, DIRK 7-3-4 at rtol 1e-9 %.8e m (%+.1e)\n",
                name, x, y, x / y - 1);
    EXPECT_NEAR(x, y, 1e-5 * y) << name;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace beamrail
