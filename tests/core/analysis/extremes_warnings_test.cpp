// Stability at the extremes (issue 6), as a user sees it: a run that passes the model's limits
// says so (a carriage driven through its rail's min_length; beams deformed beyond the small-angle
// range, in the result and in summary.json), and the same dimensionless problem in millimetres
// and in kilometres gives the same answers, also through the command line. Every case prints
// what it measured.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/static_analysis.hpp"
#include "tests/support/run_process.hpp"
#include "tests/support/scene_builder.hpp"
#include "tests/support/static_equilibrium.hpp"
#include "tests/support/transient_run.hpp"

namespace beamrail {
namespace {

using Json = nlohmann::json;
using testing::Equilibrium;
using testing::equilibrium;
using testing::Scene;
using testing::TransientRun;
using testing::vec;

constexpr double kE = 2.1e11, kG = 8.1e10;

// The beamrail executable of this build (tests/ and optimizer/ share the build directory).
std::filesystem::path beamrail_executable() {
  return std::filesystem::read_symlink("/proc/self/exe").parent_path().parent_path() / "optimizer" /
         "beamrail";
}

std::filesystem::path fresh_directory(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("beamrail_extremes_" + name + "_" + std::to_string(getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

int count_containing(const std::vector<std::string>& warnings, const std::string& part) {
  int n = 0;
  for (const std::string& w : warnings) n += w.find(part) != std::string::npos;
  return n;
}

// ---------------------------------------------------------------------------------------------
// A carriage driven along a prismatic rail through min_length and out the other side.

Scene carriage_on_rail(const std::string& formulation, double damping) {
  Scene s;
  s.material("steel", kE, kG).square("sq", 0.01);
  s.body("carriage", 2.0, Vec3(1e-4, 1e-4, 1e-4), Vec3(0.5, 0, 0));
  s.j["rails"].push_back({{"name", "guide"},
                          {"type", "prismatic"},
                          {"body1", "ground"},
                          {"body2", "carriage"},
                          {"point1", vec(0, 0, 0)},
                          {"point2", vec(0.5, 0, 0)},
                          {"point3", vec(0, 1, 0)},
                          {"material", "steel"},
                          {"section", "sq"},
                          {"formulation", formulation},
                          {"damping", damping}});
  return s;
}

TEST(Extremes, CarriageDrivenThroughMinLengthAndOutTheOtherSide) {
  // Paper force law, damped, under gravity: pushed by -2 N for 1 s and +2 N for 1 s it moves
  // from x = 0.5 to x = -0.5 (passing the rail's root at 1 m/s) and stops there; then it settles
  // on the mirrored cantilever's static deflection P a^3 / (3 E I).
  Scene s = carriage_on_rail("paper", 0.02);
  s.j["gravity"] = vec(0, -9.81, 0);
  s.force("carriage", Vec3(-2, 0, 0)).force("carriage", Vec3(4, 0, 0));
  s.j["loads"][1]["time"] = {{"type", "step"}, {"at", 1.0}};
  s.force("carriage", Vec3(-2, 0, 0));
  s.j["loads"][2]["time"] = {{"type", "step"}, {"at", 2.0}};
  const Model model = s.model();
  EXPECT_DOUBLE_EQ(model.rails[0].min_length, 5e-4);
  TransientOptions o = testing::options(6.0, 0.01, 1e-10, 1e-12);
  o.max_seconds = 20;
  const TransientRun run = testing::simulate(model, o);
  ASSERT_TRUE(run.result.ok) << run.result.message;
  double axial = 0;
  for (const auto& q : run.samples) {
    const double t = q.sample.t;
    const double exact = t <= 1   ? 0.5 - t * t / 2
                         : t <= 2 ? -(t - 1) + (t - 1) * (t - 1) / 2
                                  : -0.5;
    axial = std::max(axial, std::abs(q.c[1](0) - exact));
  }
  const double ei = kE * 1e-8 / 12, p = 2.0 * 9.81, a = 0.5;
  std::printf("  %ld steps, %ld error-test failures; |x - x_exact| <= %.2e m\n",
              run.result.stats.steps, run.result.stats.error_test_failures, axial);
  for (const std::string& w : run.result.warnings) std::printf("  warning: %s\n", w.c_str());
  EXPECT_LT(axial, 1e-8);
  const double deflection = -run.samples.back().c[1](1), exact = p * a * a * a / (3 * ei);
  std::printf("  deflection at a = -0.5 m % .12e, P a^3/(3EI) % .12e, rel. error %.2e\n",
              deflection, exact, std::abs(deflection / exact - 1));
  EXPECT_NEAR(deflection / exact, 1.0, 1e-6);
  EXPECT_EQ(count_containing(run.result.warnings, "rail \"guide\" reached its min_length"), 1);

  // Energy force law, undamped, no gravity: sliding through at 1 m/s while vibrating sideways.
  // The lateral stiffness 3 E I / l^3 grows a billion-fold near the root (capped by the floor);
  // the energy, exactly conserved by the force law, must be kept through the floor's kink.
  Scene e = carriage_on_rail("energy", 0.0);
  e.last_body()["velocity"] = vec(-1, 1e-3, 0);
  const TransientRun through = testing::simulate(e.model(), o);
  ASSERT_TRUE(through.result.ok) << through.result.message;
  const double e0 = through.samples.front().sample.energy();
  double drift = 0;
  for (const auto& q : through.samples)
    drift = std::max(drift, std::abs(q.sample.energy() / e0 - 1));
  const Vec3 end = through.samples.back().c[1];
  std::printf("  energy law: at t = 6 s x = %.6f m (moved %.6f m), energy drift %.2e, %ld steps\n",
              end(0), end(0) - 0.5, drift, through.result.stats.steps);
  EXPECT_LT(drift, 1e-6);
  EXPECT_LT(end(0), -4.0);  // it came out the other side
  EXPECT_EQ(count_containing(through.result.warnings, "rail \"guide\" reached its min_length"), 1);
}

// ---------------------------------------------------------------------------------------------
// Deformation beyond the small-angle range (|phi| > 0.5 rad) is reported as a warning, once per
// element and analysis, naming the element and the angle.

// A 1 m cantilever of 10 mm square section with a tip body, loaded by a tip torque M about z.
Scene tip_torque_cantilever(double m) {
  Scene s;
  s.material("steel", kE, kG).square("sq", 0.01);
  s.body("tip", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(1, 0, 0));
  s.beam("arm", "ground", "tip", Vec3::Zero(), Vec3(1, 0, 0), "steel", "sq");
  s.torque("tip", Vec3(0, 0, m));
  return s;
}

TEST(Extremes, DeformationBeyondTheSmallAngleRangeIsAWarning) {
  const double ei = kE * 1e-8 / 12;  // M l / EI is the tip rotation in the linear range
  const std::string arm = "beam \"arm\" deforms beyond the small-angle range";
  {
    const Equilibrium small = equilibrium(tip_torque_cantilever(0.3 * ei));
    ASSERT_TRUE(small.result.ok) << small.result.message;
    EXPECT_EQ(count_containing(small.result.warnings, "small-angle"), 0);
    const Equilibrium large = equilibrium(tip_torque_cantilever(0.8 * ei));
    ASSERT_TRUE(large.result.ok) << large.result.message;
    for (const std::string& w : large.result.warnings) std::printf("  static: %s\n", w.c_str());
    char angle[32];
    std::snprintf(angle, sizeof angle, "|phi| = %.3g rad", large.r("tip")(2));
    EXPECT_EQ(count_containing(large.result.warnings, arm), 1);
    EXPECT_EQ(count_containing(large.result.warnings, angle), 1) << angle;
  }
  {
    // A torque of 0.4 EI/l from rest overshoots to about twice the static 0.4 rad: one warning,
    // however many samples were beyond the range.
    const Model model = tip_torque_cantilever(0.4 * ei).model();
    const TransientRun run = testing::simulate(model, testing::options(0.5, 1e-3, 1e-8, 1e-10));
    ASSERT_TRUE(run.result.ok) << run.result.message;
    int beyond = 0;
    double peak = 0;
    for (const auto& x : run.samples) {
      const double angle = std::abs(rotation_vector(x.pose[1].A)(2));
      beyond += angle > 0.5;
      peak = std::max(peak, angle);
    }
    for (const std::string& w : run.result.warnings) std::printf("  transient: %s\n", w.c_str());
    std::printf("  %d of %zu samples beyond 0.5 rad, peak %.3f rad\n", beyond, run.samples.size(),
                peak);
    EXPECT_GT(beyond, 10);
    EXPECT_EQ(count_containing(run.result.warnings, arm), 1);
    // The warning's peak is that of the accepted steps, which include the rows: at least the
    // rows' peak, at most the overshoot of a step load on a linear oscillator, twice the static
    // 0.4 rad (printed to three digits).
    double reported = 0.0;
    for (const std::string& w : run.result.warnings)
      if (const size_t at = w.find("|phi| reached "); at != std::string::npos)
        reported = std::atof(w.c_str() + at + 14);
    EXPECT_GE(reported, peak - 5e-4);
    EXPECT_LE(reported, 0.8005);
  }
  {
    // A carriage turning freely on a cylindrical rail (3 rad in 1.5 s) does not deform it.
    Scene s = carriage_on_rail("energy", 0.0);
    s.j["rails"][0]["type"] = "cylindrical";
    s.last_body()["angular_velocity"] = vec(2, 0, 0);
    const TransientRun run = testing::simulate(s.model(), testing::options(1.5, 1e-2, 1e-8, 1e-10));
    ASSERT_TRUE(run.result.ok) << run.result.message;
    EXPECT_EQ(count_containing(run.result.warnings, "small-angle"), 0);
  }
}

TEST(Extremes, SmallAngleWarningReachesSummaryJson) {
  const std::filesystem::path exe = beamrail_executable();
  ASSERT_TRUE(std::filesystem::exists(exe)) << exe << " is missing: build the beamrail target";
  const std::filesystem::path dir = fresh_directory("angle");
  // The torque ramps up over 0.4 s: static at 0.8 rad, the motion peaks beyond that.
  Scene scene = tip_torque_cantilever(0.8 * kE * 1e-8 / 12);
  scene.j["loads"][0]["time"] = {{"type", "ramp"}, {"from", 0.0}, {"to", 0.4}};
  const Json transient = {{"type", "transient"}, {"t_end", 0.5}, {"output_step", 0.001}};
  const Json rotation = {{"quantity", "rotation"}, {"body", "tip"}, {"axis", vec(0, 0, 1)}};
  const Json study = {{"name", "small_angle"},
                      {"scene", scene.j},
                      {"analyses", {{{"type", "static"}}, transient}},
                      {"responses", {{"rotation", rotation}}}};
  std::ofstream(dir / "study.json") << study.dump(2);
  const testing::ProcessResult r =
      testing::run_process(exe.string(), {"run", "study.json", "-o", "out", "--quiet"}, dir);
  ASSERT_TRUE(r.exited && r.status == 0) << r.how << "\n" << r.err;
  const Json summary = Json::parse(testing::read_text(dir / "out" / "summary.json"));
  const std::vector<std::string> warnings = summary.at("warnings");
  for (const std::string& w : warnings) std::printf("  summary.json: %s\n", w.c_str());
  // One from the static analysis, one (with its time) from the transient.
  EXPECT_EQ(count_containing(warnings, "beam \"arm\" deforms beyond the small-angle range"), 2);
  EXPECT_EQ(count_containing(warnings, "reached"), 1);
  std::filesystem::remove_all(dir);
}

// ---------------------------------------------------------------------------------------------
// The same dimensionless problem in millimetres and in kilometres: a cantilever of length L
// (a rectangle L/50 wide and L/40 high, tip mass 5 L^3, inertia 0.05 L^5) under tip loads
// 250 L^2 N sideways, 75 L^2 N of compression and 12 L^3 N m of twist: deflection / L, rotations
// and frequency x L must agree. (The section is not round: a round shaft under a torque of fixed
// direction about its axis flutters (Ziegler), and the static analysis refuses it as unstable.)

Scene scaled_cantilever(double l) {
  Scene s;
  s.material("steel", kE, kG);
  s.j["sections"]["rod"] = {{"shape", "rectangle"}, {"width", l / 50}, {"height", l / 40}};
  const double m = 5 * l * l * l, j = 0.05 * l * l * l * l * l;
  s.body("tip", m, Vec3(j, j, j), Vec3(l, 0, 0));
  s.beam("arm", "ground", "tip", Vec3::Zero(), Vec3(l, 0, 0), "steel", "rod");
  s.force("tip", Vec3(-75 * l * l, 250 * l * l, 0)).torque("tip", Vec3(12 * l * l * l, 0, 0));
  return s;
}

struct ScaledAnswers {
  Vec3 displacement;  // / L
  Vec3 rotation;
  std::vector<double> frequency;  // x L [m/s]
  std::vector<std::string> warnings;
  double peak = 0, peak_time = 0;  // transient: largest tip deflection / L, its time / L
};

ScaledAnswers solve_scaled(double l) {
  const Scene s = scaled_cantilever(l);
  ScaledAnswers a;
  const Equilibrium e = equilibrium(s);
  EXPECT_TRUE(e.result.ok) << e.result.message;
  a.displacement = e.u("tip") / l;
  a.rotation = e.r("tip");
  a.warnings = e.result.warnings;
  // Modal about the loaded equilibrium.
  Data data(e.model);
  StaticOptions so;
  so.tolerance = 1e-12;
  solve_static(e.model, so, data);
  ModalOptions mo;
  const ModalResult r = solve_modal(e.model, mo, data);
  EXPECT_TRUE(r.ok) << r.message;
  for (const Mode& m : r.modes) a.frequency.push_back(m.frequency_hz * l);
  a.warnings.insert(a.warnings.end(), r.warnings.begin(), r.warnings.end());
  // Motion from rest under the loads, over two periods of mode 1, at tolerances given in the
  // units of the scene (atol scaled with L).
  const double period = l / a.frequency.at(0);
  const TransientRun run =
      testing::simulate(e.model, testing::options(2 * period, period / 400, 1e-10, 1e-10 * l));
  EXPECT_TRUE(run.result.ok) << run.result.message;
  for (const auto& x : run.samples) {
    const double y = x.c[1](1) / l;
    if (y > a.peak) a.peak = y, a.peak_time = x.sample.t / l;
  }
  return a;
}

TEST(Extremes, MillimetreAndKilometreScenesGiveTheSameDimensionlessAnswers) {
  const ScaledAnswers mm = solve_scaled(2e-3), km = solve_scaled(2e3);
  const auto compare = [](const char* what, double a, double b) {
    const double error = std::abs(a / b - 1);
    std::printf("  %-32s mm % .15e  km % .15e  rel. difference %.1e\n", what, a, b, error);
    return error;
  };
  EXPECT_LT(compare("deflection / L", mm.displacement(1), km.displacement(1)), 1e-12);
  EXPECT_LT(compare("shortening / L", mm.displacement(0), km.displacement(0)), 1e-9);
  EXPECT_LT(compare("tip rotation (z)", mm.rotation(2), km.rotation(2)), 1e-12);
  EXPECT_LT(compare("twist (x)", mm.rotation(0), km.rotation(0)), 1e-12);
  ASSERT_EQ(mm.frequency.size(), km.frequency.size());
  for (size_t k = 0; k < mm.frequency.size(); ++k) {
    char what[32];
    std::snprintf(what, sizeof what, "f%zu x L [m/s]", k + 1);
    EXPECT_LT(compare(what, mm.frequency[k], km.frequency[k]), 1e-12);
  }
  EXPECT_LT(compare("transient peak deflection / L", mm.peak, km.peak), 1e-8);
  EXPECT_LT(compare("time of the peak / L [s/m]", mm.peak_time, km.peak_time), 1e-9);
  EXPECT_EQ(mm.warnings, km.warnings);
  for (const std::string& w : mm.warnings) std::printf("  warning at both scales: %s\n", w.c_str());
}

TEST(Extremes, ScaleStudiesAgreeThroughTheCommandLine) {
  const std::filesystem::path exe = beamrail_executable();
  ASSERT_TRUE(std::filesystem::exists(exe)) << exe << " is missing: build the beamrail target";
  const std::filesystem::path studies =
      std::filesystem::path(__FILE__).parent_path().parent_path().parent_path().parent_path() /
      "studies";
  const std::filesystem::path dir = fresh_directory("scale");
  Json summary[2];
  const char* names[2] = {"scale_millimetres", "scale_kilometres"};
  for (int k = 0; k < 2; ++k) {
    const testing::ProcessResult r = testing::run_process(
        exe.string(),
        {"run", (studies / (std::string(names[k]) + ".json")).string(), "-o", names[k], "--quiet"},
        dir);
    ASSERT_TRUE(r.exited && r.status == 0) << names[k] << ": " << r.how << "\n" << r.err;
    summary[k] = Json::parse(testing::read_text(dir / names[k] / "summary.json"));
  }
  const double lengths[2] = {2e-3, 2e3};
  for (const auto& [name, power] : std::vector<std::pair<std::string, int>>{{"deflection", -1},
                                                                            {"shortening", -1},
                                                                            {"tip_rotation", 0},
                                                                            {"f1", 1},
                                                                            {"f2", 1},
                                                                            {"f6", 1}}) {
    const double a = summary[0]["responses"][name].get<double>() * std::pow(lengths[0], power);
    const double b = summary[1]["responses"][name].get<double>() * std::pow(lengths[1], power);
    std::printf("  %-14s mm % .15e  km % .15e  rel. difference %.1e\n", name.c_str(), a, b,
                std::abs(a / b - 1));
    EXPECT_LT(std::abs(a / b - 1), 1e-9) << name;
  }
  EXPECT_EQ(summary[0]["warnings"], summary[1]["warnings"]);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace beamrail
