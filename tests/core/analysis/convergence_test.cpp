// Segmented beams converge to continuum solutions at second order (docs/model.md "Validation"):
// Euler-Bernoulli frequencies (clamped-free and clamped-clamped) and the Euler elastica. Each test
// prints the errors and the observed orders log2(e_{N/2} / e_N).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/static_analysis.hpp"
#include "core/model/rotation.hpp"
#include "tests/support/scenes.hpp"

namespace beamrail {
namespace {

// A slender steel strip, 1 m, 1 mm wide (local y) and 3 mm high (local z): bending in y is the
// softest, rotary (Rayleigh) and axial-stretch corrections are below 1e-7 of the answers.
constexpr double kE = 2.1e11, kRho = 7850, kW = 1e-3, kH = 3e-3, kL = 1.0;
const double kEIz = kE * kH * kW * kW * kW / 12;

std::string strip_scene(const std::string& bodies_and_beams) {
  return R"({"materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
             "sections": {"strip": {"shape": "rectangle", "width": 0.001, "height": 0.003}},)" +
         bodies_and_beams + "}";
}

std::string segments(int n) { return std::to_string(n); }

// Frequencies [Hz] of the first `count` elastic modes that bend in y (mode shapes dominated by y).
std::vector<double> bending_frequencies_in_y(const Model& model, int count) {
  Data data(model);
  ModalOptions options;
  options.modes = std::min(4 * count + 4, model.n_dofs);  // asking for more is an error
  const ModalResult r = solve_modal(model, options, data);
  EXPECT_TRUE(r.ok) << r.message;
  std::vector<double> out;
  for (const Mode& mode : r.modes) {
    if (mode.kind != Mode::Kind::kElastic) continue;
    double y = 0, all = 0;
    for (int k = 0; k < model.n_free(); ++k) {
      y += mode.shape(6 * k + 1) * mode.shape(6 * k + 1);
      all += mode.shape.segment<3>(6 * k).squaredNorm();
    }
    if (y > 0.9 * all && static_cast<int>(out.size()) < count) out.push_back(mode.frequency_hz);
  }
  return out;
}

double euler_bernoulli_hz(double beta_l) {
  return beta_l * beta_l * std::sqrt(kEIz / (kRho * kW * kH * std::pow(kL, 4))) /
         (2 * std::numbers::pi);
}

void check_orders(const char* what, const std::vector<int>& n, const std::vector<double>& beta,
                  const std::vector<std::vector<double>>& hz) {
  for (size_t m = 0; m < beta.size(); ++m) {
    const double exact = euler_bernoulli_hz(beta[m]);
    std::printf("%s mode %zu (beta L = %.6f, %.6f Hz):\n", what, m + 1, beta[m], exact);
    double previous = 0;
    for (size_t i = 0; i < n.size(); ++i) {
      const double error = std::abs(hz[i][m] / exact - 1);
      if (i == 0)
        std::printf("  N = %2d: relative error %.3e\n", n[i], error);
      else
        std::printf("  N = %2d: relative error %.3e, observed order %.3f\n", n[i], error,
                    std::log2(previous / error));
      if (i + 1 == n.size()) {
        EXPECT_GE(std::log2(previous / error), 1.9) << what << " mode " << m + 1;
      }
      previous = error;
    }
  }
}

TEST(Convergence, CantileverFrequenciesConvergeToEulerBernoulli) {
  const std::vector<int> n{2, 4, 8, 16, 32};
  std::vector<std::vector<double>> hz;
  for (int segs : n) {
    const Model model = testing::scene_from_json(strip_scene(R"(
      "bodies": [{"name": "tip", "position": [1, 0, 0]}],
      "beams": [{"name": "strip", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
                 "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel",
                 "section": "strip", "segments": )" + segments(segs) +
                                                             "}]"));
    hz.push_back(bending_frequencies_in_y(model, 3));
    ASSERT_EQ(hz.back().size(), 3u) << "N = " << segs;
  }
  check_orders("clamped-free", n, {1.875104, 4.694091, 7.854757}, hz);
}

TEST(Convergence, ClampedClampedFrequenciesConvergeToEulerBernoulli) {
  const std::vector<int> n{4, 8, 16, 32, 64};
  std::vector<std::vector<double>> hz;
  for (int segs : n) {
    // Two halves meeting at a body that gets its mass from the segments only.
    const Model model = testing::scene_from_json(strip_scene(R"(
      "bodies": [{"name": "mid", "position": [0.5, 0, 0]}],
      "beams": [
        {"name": "left", "body1": "ground", "body2": "mid", "point1": [0, 0, 0],
         "point2": [0.5, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "strip",
         "segments": )" + segments(segs / 2) + R"(},
        {"name": "right", "body1": "mid", "body2": "ground", "point1": [0.5, 0, 0],
         "point2": [1, 0, 0], "point3": [0.5, 1, 0], "material": "steel", "section": "strip",
         "segments": )" + segments(segs / 2) + "}]"));
    hz.push_back(bending_frequencies_in_y(model, 3));
    ASSERT_EQ(hz.back().size(), 3u) << "N = " << segs;
  }
  check_orders("clamped-clamped", n, {4.730041, 7.853205, 10.995608}, hz);
}

// Euler's elastica: a cantilever under a tip load of fixed direction, P L^2 / EI = 1, 2, 5 (tip
// deflection / L and tip rotation from the elliptic-integral solution).
TEST(Convergence, SegmentedCantileverConvergesToTheElastica) {
  struct Case {
    double load, deflection, rotation;
  };
  const Case cases[] = {
      {1, 0.3017208, 0.4613519}, {2, 0.4934575, 0.7817498}, {5, 0.7137915, 1.2153681}};
  const std::vector<int> n{4, 8, 16, 32, 64};
  for (const Case& c : cases) {
    std::printf("elastica P L^2 / EI = %.0f (deflection %.7f L, rotation %.7f rad):\n", c.load,
                c.deflection, c.rotation);
    double prev_d = 0, prev_r = 0;
    for (size_t i = 0; i < n.size(); ++i) {
      char load[128];
      std::snprintf(load, sizeof load,
                    R"("loads": [{"type": "force", "body": "tip", "value": [0, %.17g, 0]}])",
                    -c.load * kEIz / (kL * kL));
      const Model model = testing::scene_from_json(strip_scene(R"(
        "bodies": [{"name": "tip", "position": [1, 0, 0]}],
        "beams": [{"name": "strip", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
                   "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel",
                   "section": "strip", "segments": )" + segments(n[i]) +
                                                               "}]," + load));
      Data data(model);
      StaticOptions options;
      options.tolerance = 1e-12;
      const StaticResult r = solve_static(model, options, data);
      ASSERT_TRUE(r.ok) << r.message;
      // The tip body's centre moved to the combined centre of mass of its half segment; follow the
      // beam end point (1, 0, 0) through the body's rotation instead.
      const int tip = 1;
      const Pose<double>& p = data.pose[tip];
      const Mat3 a0 = rotation_matrix<double>(model.bodies[tip].orientation);
      const Vec3 end_point = centre(model, data, tip) +
                             p.A * (a0.transpose() * (Vec3(kL, 0, 0) - model.bodies[tip].position));
      const double turn = rotation_vector(p.A * a0.transpose())(2);
      const double d_err = std::abs(-end_point(1) / kL / c.deflection - 1);
      const double r_err = std::abs(-turn / c.rotation - 1);
      if (i == 0) {
        std::printf(
            "  N = %2d: deflection error %.3e, rotation error %.3e (%d Newton iterations, %d load "
            "steps)\n",
            n[i], d_err, r_err, r.iterations, r.load_steps);
      } else {
        std::printf(
            "  N = %2d: deflection error %.3e (order %.3f), rotation error %.3e (order %.3f) (%d "
            "iterations, %d load steps)\n",
            n[i], d_err, std::log2(prev_d / d_err), r_err, std::log2(prev_r / r_err), r.iterations,
            r.load_steps);
        if (i + 1 == n.size()) {
          EXPECT_NEAR(std::log2(prev_d / d_err), 2.0, 0.15);
          EXPECT_NEAR(std::log2(prev_r / r_err), 2.0, 0.15);
        }
      }
      prev_d = d_err, prev_r = r_err;
    }
  }
}

}  // namespace
}  // namespace beamrail
