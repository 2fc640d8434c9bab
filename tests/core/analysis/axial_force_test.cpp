// The beam law leaves out what an element's own axial force does to its bending (no P-delta
// within an element, docs/model.md "Axial force and bending"): segments recover it at second
// order, and the static, modal, buckling and transient analyses warn where their estimates
// (core/analysis/axial_force_check.hpp, core/analysis/axial_force_watch.hpp) pass 1 %. Checked
// against the closed forms of a cantilever under an axial force and a small side load at its
// tip, against many segments, and, for a transient, against the 1/n^2 limit of tight runs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <tuple>
#include <vector>

#include "core/analysis/axial_force_check.hpp"
#include "core/analysis/buckling_analysis.hpp"
#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/static_analysis.hpp"
#include "core/analysis/transient.hpp"
#include "tests/support/scenes.hpp"
#include "tests/support/transient_run.hpp"

namespace beamrail {
namespace {

constexpr double kE = 2.1e11;
constexpr double kLength = 2.0;
constexpr double kSide = 100.0;  // [N]

// A 2 m steel box column (80 x 60 x 4 mm; a density of 1 kg/m^3, which segments need, so that
// the 50 kg head carries the inertia) clamped at z = 0 with a head at z = 2 under an axial
// force `axial` (< 0: compression) and kSide along global y, its weak direction (the box's
// height, 60 mm, lies along local z = global y).
// With `side_at` >= 0, the side load is a step at that time [s] (0 before it).
std::string column(double axial, int segments, double side = kSide, bool reversed = false,
                   double density = 1.0, double side_at = -1.0) {
  const std::string side_load =
      side_at >= 0.0
          ? R"(, {"type": "force", "body": "head", "value": [0, )" + std::to_string(side) +
                R"(, 0], "time": {"type": "step", "at": )" + std::to_string(side_at) + "}}"
          : "";
  if (side_at >= 0.0) side = 0.0;
  return R"({"materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": )" +
         std::to_string(density) + R"(}},
    "sections": {"box": {"shape": "box", "width": 0.08, "height": 0.06, "wall": 0.004}},
    "bodies": [{"name": "head", "mass": 50, "inertia": [0.5, 0.5, 0.5], "position": [0, 0, 2]}],
    "beams": [{"name": "column", )" +
         std::string(reversed ? R"("body1": "head", "body2": "ground", "point1": [0, 0, 2],
               "point2": [0, 0, 0], "point3": [1, 0, 2],)"
                              : R"("body1": "ground", "body2": "head", "point1": [0, 0, 0],
               "point2": [0, 0, 2], "point3": [1, 0, 0],)") +
         R"( "material": "steel", "section": "box", "segments": )" + std::to_string(segments) +
         R"(}],
    "loads": [{"type": "force", "body": "head", "value": [0, )" +
         std::to_string(side) + ", " + std::to_string(axial) + "]}" + side_load + "]}";
}

// The weak axis's EI: Iy = (w h^3 - wi hi^3) / 12.
double weak_ei() {
  const double w = 0.08, h = 0.06, t = 0.004;
  return kE * (w * h * h * h - (w - 2 * t) * std::pow(h - 2 * t, 3)) / 12.0;
}

// The tip's side deflection of a cantilever under an axial force N (its direction fixed, as the
// scene's load) and a side load F at the tip, a^2 = |N| / EI: in compression
// F (tan aL - aL) / (|N| a), in tension F (aL - tanh aL) / (N a).
double exact_sway(double axial) {
  const double a = std::sqrt(std::abs(axial) / weak_ei()), al = a * kLength;
  return axial < 0.0 ? kSide * (std::tan(al) - al) / (-axial * a)
                     : kSide * (al - std::tanh(al)) / (axial * a);
}

struct Solved {
  double sway = 0.0;       // the head's displacement along y [m]
  double moved = 0.0;      // |u| of the head [m]
  double estimate = -1;    // the static warning's value, -1 without one
  double modal = -1;       // the modal warning's value, -1 without one
  double frequency = 0.0;  // the lowest mode's [Hz]
  std::string warning, modal_warning;
};

// The value a warning gives after `after`, -1 when no warning names the axial forces.
double warned(const std::vector<std::string>& warnings, const std::string& after,
              std::string* text) {
  for (const std::string& w : warnings) {
    if (w.find("axial forces") == std::string::npos) continue;
    *text = w;
    const size_t at = w.find(after);
    if (at != std::string::npos) return std::stod(w.substr(at + after.size()));
  }
  return -1.0;
}

// The static equilibrium, then its modes (about it).
Solved solve(double axial, int segments, bool reversed = false) {
  const Model model = testing::scene_from_json(column(axial, segments, kSide, reversed));
  Data data(model);
  StaticOptions options;
  options.tolerance = 1e-12;
  const StaticResult result = solve_static(model, options, data);
  EXPECT_TRUE(result.ok) << result.message;
  Solved run;
  const int head = testing::body_index(model, "head");
  run.sway = data.pose[head].u.y();
  run.moved = data.pose[head].u.norm();
  run.estimate = warned(result.warnings, "displacements by about ", &run.warning);
  ModalOptions modal;
  modal.modes = 1;
  const ModalResult modes = solve_modal(model, modal, data);
  EXPECT_TRUE(modes.ok) << modes.message;
  for (const Mode& m : modes.modes)
    if (m.kind == Mode::Kind::kElastic) {
      run.frequency = m.frequency_hz;
      break;
    }
  run.modal = warned(modes.warnings, "by about ", &run.modal_warning);
  return run;
}

// 60 kN of compression (0.78 of Euler's 77.25 kN) and 2 kN of tension, the column's element(s)
// from the ground up and from the head down (the left end turning with the head). The static
// warning's value is each body's correction over its displacement along it, measured by
// iterating on the analysis's own factorization; here against the closed form, relative to the
// side deflection computed. The modal one is the lowest mode's relative change by the Rayleigh
// quotient, against the frequency of 64 segments (converged to 2e-4 at 0.78 of the buckling
// load: 32 segments differ from it by that).
TEST(AxialForce, TheStaticAndModalAnalysesWarnWhatTheBeamsOwnAxialForcesLeaveOut) {
  for (bool reversed : {false, true})
    for (double axial : {-60e3, 2e3}) {
      const double exact = exact_sway(axial);
      const double converged = solve(axial, 64, reversed).frequency;
      for (int segments : {0, 4, 8, 16}) {
        const Solved run = solve(axial, segments, reversed);
        const double error = std::abs(exact / run.sway - 1.0);
        const double frequency_error = std::abs(converged / run.frequency - 1.0);
        std::printf(
            "%s, N %+.0f N, %2d segments: sway %.6e m (exact %.6e): error %.3g, "
            "warning's %.3g; f1 %.6g Hz (64 segments: %.6g): error %.3g, warning's %.3g\n",
            reversed ? "from the head" : "from the ground", axial, segments, run.sway, exact, error,
            run.estimate, run.frequency, converged, frequency_error, run.modal);
        for (const auto& [what, truth, value] :
             {std::tuple<const char*, double, double>{"static", error, run.estimate},
              {"modal", frequency_error, run.modal}}) {
          if (truth > 1.5 * kAxialForceWarning) {
            ASSERT_GT(value, 0.0) << what << ": no warning at " << segments;
            EXPECT_GT(value, 0.7 * truth) << what << " " << segments;
            EXPECT_LT(value, 1.3 * truth) << what << " " << segments;
          } else if (truth < 0.5 * kAxialForceWarning) {
            EXPECT_EQ(value, -1.0) << what << ": a warning at " << segments;
          }
        }
      }
    }
}

// A perfect column (no side load) at 1.2 times its Euler load: in one element it stands, with
// nothing sideways to correct; 64 segments find it unstable. The static analysis says it would
// buckle.
TEST(AxialForce, APerfectColumnPastItsBucklingLoadIsReportedUnstable) {
  const double euler = M_PI * M_PI * weak_ei() / (4.0 * kLength * kLength);
  for (int segments : {0, 64}) {
    const Model model = testing::scene_from_json(column(-1.2 * euler, segments, 0.0));
    Data data(model);
    const StaticResult result = solve_static(model, StaticOptions{}, data);
    std::string text;
    for (const std::string& w : result.warnings)
      if (w.find("axial forces") != std::string::npos) text = w;
    std::printf("%2d segments: %s; %s\n", segments, result.ok ? "ok" : result.message.c_str(),
                text.c_str());
    if (segments == 0) {
      ASSERT_TRUE(result.ok) << result.message;
      EXPECT_NE(text.find("would make this equilibrium unstable"), std::string::npos) << text;
    } else {
      EXPECT_FALSE(result.ok);
      EXPECT_NE(result.message.find("unstable"), std::string::npos) << result.message;
    }
  }
}

// The buckling factor of 1 kN of compression against Euler's pi^2 EI / (4 L^2) = 77.25 kN: each
// element leaves out its own stress stiffness, so segments converge from above; the warning's
// value (the Rayleigh quotient with the missing stiffness of the forces per unit factor) against
// the factor's error. One element finds no factor and says why.
TEST(AxialForce, BucklingWarnsWhatTheBeamsOwnAxialForcesLeaveOut) {
  const double euler = M_PI * M_PI * weak_ei() / (4.0 * kLength * kLength) / 1000.0;
  for (int segments : {0, 2, 4, 8, 16, 32}) {
    const Model model = testing::scene_from_json(column(-1000.0, segments, 0.0));
    Data data(model);
    const Model reference = with_loads(
        model, [](const Load&) { return false; }, false);
    BucklingOptions options;
    options.modes = 1;
    const BucklingResult result = solve_buckling(reference, model, options, data);
    ASSERT_TRUE(result.ok) << result.message;
    std::string text;
    const double value = warned(result.warnings, "by about ", &text);
    if (segments == 0) {
      ASSERT_TRUE(result.modes.empty());
      bool named = false;
      for (const std::string& w : result.warnings)
        named = named || w.find("beam \"column\" is one element") != std::string::npos;
      EXPECT_TRUE(named);
      continue;
    }
    ASSERT_FALSE(result.modes.empty());
    const double factor = result.modes[0].factor;
    const double error = std::abs(euler / factor - 1.0);
    std::printf("%2d segments: factor %.6g (Euler %.6g): error %.3g, warning's %.3g\n", segments,
                factor, euler, error, value);
    if (error > 1.5 * kAxialForceWarning) {
      ASSERT_GT(value, 0.0) << "no warning at " << segments << ": " << text;
      EXPECT_GT(value, 0.7 * error) << segments;
      EXPECT_LT(value, 1.3 * error) << segments;
    } else if (error < 0.5 * kAxialForceWarning) {
      EXPECT_EQ(value, -1.0) << "a warning at " << segments << ": " << text;
    }
  }
}

// A transient by auto from the static equilibrium of the loads at t = 0 (*st: that analysis).
testing::TransientRun from_equilibrium(const Model& model, TransientOptions options,
                                       StaticResult* st) {
  Data equilibrium(model);
  StaticOptions at_start;
  at_start.time = 0.0;
  *st = solve_static(model, at_start, equilibrium);
  options.integrator.method = IntegratorMethod::kAuto;
  options.initial_state.resize(model.n_states);
  initial_state_at(model, equilibrium, options.initial_state.data());
  return testing::simulate(model, options);
}

// A transient from the equilibrium under the axial force (60 kN of compression, 0.78 of
// Euler's load), the side load a step at 10 ms: the head swings to about twice the static sway
// and back. The warning's value (the largest relative change of the deformation the missing
// stiffness makes, over the states measured) against the error of the largest sway over the
// output samples, relative to its limit for many segments: the Richardson extrapolation of 16
// and 32 segments (the observed order printed). The column's own mass is kept small (density
// 100: 0.22 kg against the head's 50 kg) so that the segments change its stiffness, not its
// inertia; 64 segments, 13 s, gave the same limit within 1e-6 of it.
TEST(AxialForce, ATransientWarnsWhatTheBeamsOwnAxialForcesLeaveOut) {
  const auto peak = [](int segments, double* warning, TransientResult* out) {
    const Model model =
        testing::scene_from_json(column(-60e3, segments, kSide, false, 100.0, 0.01));
    StaticResult st;
    const testing::TransientRun run =
        from_equilibrium(model, testing::options(0.5, 0.005, 1e-6, 1e-10), &st);
    EXPECT_TRUE(st.ok) << st.message;
    EXPECT_TRUE(run.result.ok) << run.result.message;
    const int head = testing::body_index(model, "head");
    double most = 0.0;
    for (const testing::Snapshot& snap : run.samples)
      most = std::max(most, std::abs(snap.pose[head].u.y()));
    std::string text;
    *warning = warned(run.result.warnings, "deformation by about ", &text);
    if (out) *out = run.result;
    return most;
  };
  double unused;
  const double p16 = peak(16, &unused, nullptr), p32 = peak(32, &unused, nullptr);
  const double limit = p32 + (p32 - p16) / 3.0;
  for (int segments : {4, 8}) {
    double value = -1.0;
    TransientResult result;
    const double p = peak(segments, &value, &result);
    const double error = std::abs(p / limit - 1.0);
    std::printf(
        "%d segments: largest sway %.6e m (limit %.6e): error %.3g, warning's %.3g at t = %g s "
        "(%d states measured)\n",
        segments, p, limit, error, value, result.axial_force_time, result.axial_force_states);
    ASSERT_GT(value, 0.0) << "no warning at " << segments;
    EXPECT_NEAR(value, result.axial_force_effect, 5e-3 * value);  // the warning's 3 digits
    EXPECT_GT(value, 0.7 * error) << segments;
    EXPECT_LT(value, 1.3 * error) << segments;
    if (segments == 8) {
      std::printf("observed order of 8, 16, 32 segments: %.2f\n",
                  std::log2((p16 - p) / (p32 - p16)));
      EXPECT_NEAR(std::log2((p16 - p) / (p32 - p16)), 2.0, 0.2);
    }
  }
}

// At an equilibrium a transient measures what the static analysis does: the column under 2 kN
// of tension and the side load from the start (the run stays at its static equilibrium), against
// the closed form. One element leaves out 2.5 % of the sway and warns; four leave out 0.14 % and
// do not.
TEST(AxialForce, ATransientAtAnEquilibriumWarnsAsTheStaticAnalysis) {
  for (int segments : {0, 4}) {
    const Model model = testing::scene_from_json(column(2e3, segments));
    StaticResult st;
    const testing::TransientRun run =
        from_equilibrium(model, testing::options(0.02, 0.01, 1e-6, 1e-12), &st);
    ASSERT_TRUE(st.ok) << st.message;
    ASSERT_TRUE(run.result.ok) << run.result.message;
    const int head = testing::body_index(model, "head");
    const double error = std::abs(exact_sway(2e3) / run.samples.back().pose[head].u.y() - 1.0);
    std::string text, static_text;
    const double value = warned(run.result.warnings, "deformation by about ", &text);
    const double static_value = warned(st.warnings, "displacements by about ", &static_text);
    std::printf("%d segments: error %.3g; the transient's warning %.3g, the static one's %.3g\n",
                segments, error, value, static_value);
    EXPECT_EQ(run.result.axial_force_states, 3);  // t = 0, 0.01, 0.02
    if (segments == 0) {
      ASSERT_GT(value, 0.0) << text;
      EXPECT_GT(value, 0.7 * error);
      EXPECT_LT(value, 1.3 * error);
      EXPECT_NEAR(value, static_value, 0.2 * static_value);
    } else {
      EXPECT_LT(error, 0.5 * kAxialForceWarning);
      EXPECT_EQ(value, -1.0) << text;
      EXPECT_LT(run.result.axial_force_effect, 0.5 * kAxialForceWarning);
    }
  }
}

}  // namespace
}  // namespace beamrail
