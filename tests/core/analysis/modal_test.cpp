// Modal analysis against closed forms (docs/model.md "Validation"), rigid-body modes, and dense vs
// Spectra.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "core/analysis/modal_analysis.hpp"
#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"
#include "tests/support/closed_forms.hpp"
#include "tests/support/scenes.hpp"

namespace beamrail {
namespace {

constexpr double kPi = std::numbers::pi;

std::string num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

using testing::bending_pair;

TEST(Modal, TipBodyWithRotaryInertiaAndOffsetMatchesTheTwoByTwoClosedForm) {
  const double e_mod = 2.1e11, g_mod = 8.0769e10, l = 0.9, w = 0.01, h = 0.014;
  const double m = 1.7, e = 0.05, jxx = 2e-3, jyy = 3e-3, jzz = 4e-3;
  const std::string json = R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"s": {"shape": "rectangle", "width": 0.01, "height": 0.014}},
    "bodies": [{"name": "tip", "mass": 1.7, "inertia": [2e-3, 3e-3, 4e-3],
                "position": [)" +
                           num(l + e) + R"(, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [)" +
                           num(l) + R"(, 0, 0], "point3": [0, 1, 0], "material": "steel",
               "section": "s"}]})";
  const Model model = testing::scene_from_json(json);
  Data data(model);
  ModalOptions options;
  options.modes = 6;
  const ModalResult r = solve_modal(model, options, data);
  ASSERT_TRUE(r.ok) << r.message;
  ASSERT_EQ(r.modes.size(), 6u);
  EXPECT_EQ(r.rigid_modes, 0);

  const double iz = h * w * w * w / 12, iy = w * h * h * h / 12;
  const Beam& beam = model.beams[0];
  std::vector<double> exact{e_mod * w * h / (l * m), beam.gj / (l * jxx)};
  for (double v : bending_pair(e_mod * iz, l, m, jzz, e)) exact.push_back(v);  // in y, about z
  for (double v : bending_pair(e_mod * iy, l, m, jyy, e)) exact.push_back(v);  // in z, about y
  std::sort(exact.begin(), exact.end());
  (void)g_mod;
  double worst = 0;
  for (size_t i = 0; i < 6; ++i) {
    const double f_exact = std::sqrt(exact[i]) / (2 * kPi);
    const double err = std::abs(r.modes[i].frequency_hz / f_exact - 1);
    std::printf("mode %zu: %.12e Hz, closed form %.12e Hz, relative error %.2e\n", i + 1,
                r.modes[i].frequency_hz, f_exact, err);
    worst = std::max(worst, err);
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_LT(r.asymmetry, 1e-12);
}

// Two bodies joined by one beam, floating: six rigid-body modes with frequency exactly zero, and
// the axial mode at sqrt(k (1/m1 + 1/m2)).
TEST(Modal, FreeFloatingSceneHasSixRigidModesAndCorrectElasticModes) {
  const Model model = testing::scene_from_json(R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.1e10}},
    "sections": {"rod": {"shape": "circle", "diameter": 0.01}},
    "bodies": [
      {"name": "a", "mass": 2.0, "inertia": [1e-3, 2e-3, 2e-3], "position": [0, 0, 0]},
      {"name": "b", "mass": 3.0, "inertia": [2e-3, 3e-3, 3e-3], "position": [1, 0, 0]}],
    "beams": [{"name": "ab", "body1": "a", "body2": "b", "point1": [0, 0, 0], "point2": [1, 0, 0],
               "point3": [0, 1, 0], "material": "steel", "section": "rod"}]})");
  Data data(model);
  ModalOptions options;
  options.modes = 6;
  const ModalResult r = solve_modal(model, options, data);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.rigid_modes, 6);
  int unstable = 0;
  for (const Mode& mode : r.modes) {
    if (mode.kind == Mode::Kind::kRigid) {
      EXPECT_EQ(mode.frequency_hz, 0.0);
    }
    unstable += mode.kind == Mode::Kind::kUnstable;
  }
  EXPECT_EQ(unstable, 0);
  // Torsion: two inertias on a torsion spring; axial: two masses on a spring.
  const double k_axial = model.beams[0].ea / 1.0, k_torsion = model.beams[0].gj / 1.0;
  const double axial = std::sqrt(k_axial * (1 / 2.0 + 1 / 3.0)) / (2 * kPi);
  const double torsion = std::sqrt(k_torsion * (1 / 1e-3 + 1 / 2e-3)) / (2 * kPi);
  double best_axial = 1e9, best_torsion = 1e9;
  for (int k = 1; k <= 6; ++k) {
    const Mode* mode = elastic_mode(r, k);
    ASSERT_NE(mode, nullptr);
    best_axial = std::min(best_axial, std::abs(mode->frequency_hz / axial - 1));
    best_torsion = std::min(best_torsion, std::abs(mode->frequency_hz / torsion - 1));
  }
  std::printf(
      "floating pair: %d rigid modes; axial %.6f Hz (error %.1e), torsion %.6f Hz (error "
      "%.1e)\n",
      r.rigid_modes, axial, best_axial, torsion, best_torsion);
  EXPECT_LT(best_axial, 1e-9);
  EXPECT_LT(best_torsion, 1e-9);
}

// A 40-segment cantilever: the dense solver and Spectra's shift-invert agree. The dense solver
// resolves an eigenvalue lambda_k only to ~eps lambda_max / lambda_k relative (here ~1e-10 for
// the first mode: the stiff axial modes of short segments set lambda_max), so that is the bound.
TEST(Modal, DenseAndShiftInvertSolversAgree) {
  const Model model = testing::scene_from_json(R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.012}},
    "bodies": [{"name": "tip", "position": [1, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq",
               "segments": 40}]})");
  ASSERT_EQ(model.n_dofs, 240);
  ModalOptions options;
  options.modes = 8;
  options.solver = EigenSolverKind::kDense;
  Data d1(model), d2(model);
  const ModalResult dense = solve_modal(model, options, d1);
  options.solver = EigenSolverKind::kShiftInvert;
  const ModalResult sparse = solve_modal(model, options, d2);
  ASSERT_TRUE(dense.ok) << dense.message;
  ASSERT_TRUE(sparse.ok) << sparse.message;
  EXPECT_EQ(sparse.solver, "shift-invert");
  double lambda_max = 0;
  for (const Mode& mode : dense.modes) lambda_max = std::max(lambda_max, mode.eigenvalue);
  Data d3(model);
  options.solver = EigenSolverKind::kDense;
  options.modes = 240;
  const ModalResult all = solve_modal(model, options, d3);
  for (const Mode& mode : all.modes) lambda_max = std::max(lambda_max, mode.eigenvalue);
  double worst = 0;
  for (int k = 1; k <= 8; ++k) {
    const double a = elastic_mode(dense, k)->frequency_hz,
                 b = elastic_mode(sparse, k)->frequency_hz;
    const double bound =
        std::max(1e-12, 2.2e-16 * lambda_max / elastic_mode(sparse, k)->eigenvalue);
    EXPECT_LT(std::abs(a / b - 1), bound) << "mode " << k;
    worst = std::max(worst, std::abs(a / b - 1) / bound);
    // Same shape up to rounding (both normalized, sign fixed).
    const Eigen::VectorXd& x = elastic_mode(dense, k)->shape;
    const Eigen::VectorXd& y = elastic_mode(sparse, k)->shape;
    EXPECT_LT(std::min((x - y).norm(), (x + y).norm()) / x.norm(), 1e-6) << "mode " << k;
  }
  std::printf(
      "dense vs shift-invert, 8 modes of a 40-segment cantilever: worst difference %.3f of "
      "the bound eps lambda_max / lambda_k (lambda_max %.3e)\n",
      worst, lambda_max);
  // Spectra's pairs satisfy K x = lambda M x to its tolerance (1e-12) plus rounding, which is
  // again ~eps lambda_max / lambda_k relative (the residual sums stiff entries that cancel); 10 eps
  // allows for the accumulation over a row.
  compute_tangent(model, d2, options.time, false);
  const Eigen::SparseMatrix<double> k = -stiffness_matrix(model, d2), m = mass_matrix(model, d2);
  double residual = 0;
  for (int i = 1; i <= 8; ++i) {
    const Mode* mode = elastic_mode(sparse, i);
    const double r = (k * mode->shape - mode->eigenvalue * (m * mode->shape)).norm() /
                     (mode->eigenvalue * (m * mode->shape).norm());
    const double bound = 1e-12 + 10 * 2.2e-16 * lambda_max / mode->eigenvalue;
    EXPECT_LT(r, bound) << "mode " << i;
    residual = std::max(residual, r / bound);
  }
  std::printf(
      "shift-invert eigenpair residual: worst %.3f of 1e-12 + 10 eps lambda_max / lambda_k\n",
      residual);
}

}  // namespace
}  // namespace beamrail
