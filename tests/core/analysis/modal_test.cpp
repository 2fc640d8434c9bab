// Modal analysis against closed forms (docs/model.md "Validation"), rigid-body modes, dense vs
// Spectra, the solver kAuto chooses, shift-invert with a topology's shared ordering against the
// solution of before, and a portal frame converging to its exact frequencies (the dynamic
// stiffness of its members).
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/sparse_structure.hpp"
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

// About the unloaded initial configuration (load_factor 0, "about": "initial") the loads take no
// part, harmonic ones too: they have no final value (NaN at the default time, t = infinity), and 0
// times NaN made the tangent NaN, so that the eigensolver failed (an adversarial review,
// 2026-11-30). A harmonic force and a harmonic follower torque on the tip: the frequencies of the
// scene without loads, to the bit.
TEST(Modal, AboutTheInitialConfigurationHarmonicLoadsTakeNoPart) {
  const std::string scene = R"(
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"s": {"shape": "rectangle", "width": 0.01, "height": 0.014}},
    "bodies": [{"name": "tip", "mass": 1.7, "inertia": [2e-3, 3e-3, 4e-3], "position": [0.9, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [0.9, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "s"}])";
  const Model plain = testing::scene_from_json("{" + scene + "}");
  const Model loaded = testing::scene_from_json("{" + scene + R"(,
    "loads": [{"type": "force", "body": "tip", "value": [0, 0, 200],
               "time": {"type": "harmonic", "frequency": 1.0}},
              {"type": "torque", "body": "tip", "value": [0, 50, 0], "follows": true,
               "time": {"type": "harmonic", "frequency": 3.0, "phase": 0.5}}]})");
  ModalOptions options;
  options.modes = 6;
  options.load_factor = 0.0;
  ASSERT_TRUE(std::isinf(options.time));
  Data plain_data(plain), loaded_data(loaded);
  const ModalResult expected = solve_modal(plain, options, plain_data);
  const ModalResult r = solve_modal(loaded, options, loaded_data);
  ASSERT_TRUE(expected.ok) << expected.message;
  ASSERT_TRUE(r.ok) << r.message;
  ASSERT_EQ(r.modes.size(), expected.modes.size());
  for (size_t i = 0; i < r.modes.size(); ++i) {
    std::printf("mode %zu: %.12e Hz, without the loads %.12e Hz\n", i + 1, r.modes[i].frequency_hz,
                expected.modes[i].frequency_hz);
    EXPECT_EQ(r.modes[i].frequency_hz, expected.modes[i].frequency_hz) << i;
  }
  EXPECT_GT(r.modes[0].frequency_hz, 1.0);
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

// The portal frame of studies/portal_frame.json (two 3 m columns, a 4 m girder, 60 x 60 x 4 mm
// steel box, distributed mass), unloaded, each member in `segments` segments; `wall` the box's
// wall [m]. Floating: the columns stand on a free 200 kg base instead of the ground (six rigid
// modes, a shift mu > 0).
std::string portal_frame(int segments, double wall = 0.004, bool floating = false) {
  const std::string n = std::to_string(segments);
  const std::string base = floating ? "base" : "ground";
  return R"({"materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"box": {"shape": "box", "width": 0.06, "height": 0.06, "wall": )" +
         num(wall) + R"(}},
    "bodies": [)" +
         (floating ? R"({"name": "base", "mass": 200, "inertia": [50, 300, 300],
                        "position": [2, 0, 0]}, )"
                   : std::string()) +
         R"({"name": "knee_left", "position": [0, 0, 3]},
               {"name": "knee_right", "position": [4, 0, 3]}],
    "beams": [
      {"name": "column_left", "body1": ")" +
         base + R"(", "body2": "knee_left", "point1": [0, 0, 0],
       "point2": [0, 0, 3], "point3": [1, 0, 0], "material": "steel", "section": "box",
       "segments": )" +
         n + R"(},
      {"name": "column_right", "body1": ")" +
         base + R"(", "body2": "knee_right", "point1": [4, 0, 0],
       "point2": [4, 0, 3], "point3": [5, 0, 0], "material": "steel", "section": "box",
       "segments": )" +
         n + R"(},
      {"name": "girder", "body1": "knee_left", "body2": "knee_right", "point1": [0, 0, 3],
       "point2": [4, 0, 3], "point3": [0, 0, 4], "material": "steel", "section": "box",
       "segments": )" +
         n + R"(}]})";
}

// kAuto takes the dense solver only below p + 12 degrees of freedom, p the pairs Lanczos would
// compute (the modes wanted; 12 more when a body is not held by beams), where it measured faster,
// and where Lanczos cannot run (below 2 p).
TEST(Modal, AutoTakesTheDenseSolverOnlyWhereItIsFaster) {
  const auto solver = [](const std::string& json, int modes) {
    const Model model = testing::scene_from_json(json);
    Data data(model);
    ModalOptions options;
    options.modes = modes;
    const ModalResult r = solve_modal(model, options, data);
    EXPECT_TRUE(r.ok) << r.message;
    return std::to_string(model.n_dofs) + " " + r.solver;
  };
  EXPECT_EQ(solver(portal_frame(1), 1), "12 dense");  // 12 < 1 + 12
  EXPECT_EQ(solver(portal_frame(2), 6), "30 shift-invert");
  EXPECT_EQ(solver(portal_frame(2), 15), "30 shift-invert");
  EXPECT_EQ(solver(portal_frame(2), 16), "30 dense");  // 30 < 2 x 16
  EXPECT_EQ(solver(portal_frame(32), 6), "570 shift-invert");
  EXPECT_EQ(solver(portal_frame(2, 0.004, true), 6), "36 shift-invert");  // p = 6 + 12
  EXPECT_EQ(solver(portal_frame(2, 0.004, true), 8), "36 dense");         // 36 < 2 (8 + 12)
  EXPECT_TRUE(modal_dense_is_faster(29, 18));
  EXPECT_FALSE(modal_dense_is_faster(30, 18));
}

// y = (K - sigma M)^-1 x as solve_modal computed it before the topology's ordering was shared
// (commit 3d0c4b1): Eigen's SimplicialLDLT of the sparse sum K - sigma M, its own ordering.
class FormerShiftSolve {
 public:
  using Scalar = double;
  FormerShiftSolve(const Eigen::SparseMatrix<double>& k, const Eigen::SparseMatrix<double>& m)
      : k_(k), m_(m) {}
  Eigen::Index rows() const { return k_.rows(); }
  Eigen::Index cols() const { return k_.cols(); }
  void set_shift(double sigma) {
    const Eigen::SparseMatrix<double> a = k_ - sigma * m_;
    ldlt_.compute(a);
    ASSERT_EQ(ldlt_.info(), Eigen::Success);
  }
  void perform_op(const double* x, double* y) const {
    Eigen::Map<Eigen::VectorXd>(y, rows()) =
        ldlt_.solve(Eigen::Map<const Eigen::VectorXd>(x, rows()));
  }

 private:
  const Eigen::SparseMatrix<double>& k_;
  const Eigen::SparseMatrix<double>& m_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt_;
};

// The `count` eigenpairs nearest -shift of the model's K x = w^2 M x about its initial state as
// solve_modal found them before (Spectra's shift-invert Lanczos with FormerShiftSolve, ncv =
// max(2 count + 1, 20)), ascending, each vector scaled as solve_modal scales a shape (x^T M x = 1,
// its largest entry positive).
struct Pairs {
  std::vector<double> values;
  std::vector<Eigen::VectorXd> shapes;
};
Pairs former_shift_invert(const Model& model, double shift, Eigen::Index count) {
  Data data(model);
  ModalOptions options;
  compute_wrenches(model, data, options.time, options.load_factor);
  compute_tangent(model, data, options.time, false, options.load_factor);
  const Eigen::SparseMatrix<double> m = mass_matrix(model, data);
  const Eigen::SparseMatrix<double> k = symmetric_stiffness(
      model, data, Eigen::VectorXd(m.diagonal()).cwiseSqrt().cwiseInverse(), nullptr);
  FormerShiftSolve op(k, m);
  Spectra::SparseSymMatProd<double> bop(m);
  const Eigen::Index ncv = std::max<Eigen::Index>(2 * count + 1, 20);
  Spectra::SymGEigsShiftSolver<FormerShiftSolve, Spectra::SparseSymMatProd<double>,
                               Spectra::GEigsMode::ShiftInvert>
      eigs(op, bop, count, ncv, -shift);
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestMagn, 1000, 1e-12);
  EXPECT_EQ(eigs.info(), Spectra::CompInfo::Successful);
  const Eigen::VectorXd values = eigs.eigenvalues();
  const Eigen::MatrixXd vectors = eigs.eigenvectors();
  std::vector<Eigen::Index> order(static_cast<size_t>(values.size()));
  for (Eigen::Index i = 0; i < values.size(); ++i) order[static_cast<size_t>(i)] = i;
  std::sort(order.begin(), order.end(),
            [&](Eigen::Index a, Eigen::Index b) { return values(a) < values(b); });
  Pairs out;
  for (Eigen::Index i : order) {
    Eigen::VectorXd x = vectors.col(i);
    x /= std::sqrt(x.dot(m * x));
    Eigen::Index big = 0;
    x.cwiseAbs().maxCoeff(&big);
    if (x(big) < 0) x = -x;
    out.values.push_back(values(i));
    out.shapes.push_back(x);
  }
  return out;
}

// The designs of one topology share the fill-reducing ordering of K + mu M through a
// SparseStructureCache: computed once per topology (a held frame, mu = 0, and a floating one,
// mu > 0), and every design's modes equal those of its analysis without the cache to the last
// bit. Against the solver of before: the floating frame, whose Lanczos still computes the wanted
// modes plus 12 for the rigid ones, gives the same frequencies and shapes to the last bit; the held
// one, whose Lanczos now computes the wanted modes only (0.88 -> 0.44 s for 10 modes of
// 100,000 degrees of freedom), the same frequencies within 1e-12 (measured 4e-15) and shapes
// within 1e-9 (measured 3e-14).
TEST(Modal, DesignsShareTheOrderingAndKeepTheirModesToTheBit) {
  SparseStructureCache cache;
  const int wanted = 6;
  for (const bool floating : {false, true}) {
    for (const double wall : {0.004, 0.005}) {
      const Model model = testing::scene_from_json(portal_frame(32, wall, floating));
      ModalOptions options;
      options.modes = wanted;
      Data d1(model), d2(model);
      const ModalResult alone = solve_modal(model, options, d1);
      options.structure_cache = &cache;
      const ModalResult shared = solve_modal(model, options, d2);
      ASSERT_TRUE(alone.ok && shared.ok) << alone.message << shared.message;
      EXPECT_EQ(shared.solver, "shift-invert");
      EXPECT_EQ(alone.rigid_modes, floating ? 6 : 0);
      ASSERT_EQ(alone.modes.size(), shared.modes.size());
      for (size_t i = 0; i < alone.modes.size(); ++i) {
        EXPECT_EQ(alone.modes[i].eigenvalue, shared.modes[i].eigenvalue) << i;
        EXPECT_TRUE(alone.modes[i].shape == shared.modes[i].shape) << i;
      }
      const Pairs former = former_shift_invert(
          model, alone.shift, std::min<Eigen::Index>(model.n_dofs - 1, wanted + 12));
      double worst_value = 0, worst_shape = 0;
      for (int k = 1; k <= wanted; ++k) {
        const Mode* mode = elastic_mode(alone, k);
        ASSERT_NE(mode, nullptr);
        const size_t j = static_cast<size_t>(alone.rigid_modes + k - 1);
        const double value = former.values.at(j);
        const Eigen::VectorXd& shape = former.shapes.at(j);
        if (floating) {
          EXPECT_EQ(mode->eigenvalue, value) << k;
          EXPECT_TRUE(mode->shape == shape) << k;
        }
        worst_value = std::max(worst_value, std::abs(mode->eigenvalue / value - 1));
        worst_shape = std::max(worst_shape, (mode->shape - shape).norm() / shape.norm());
      }
      std::printf(
          "%s frame, wall %.0f mm: %d modes, against the former solver: frequencies "
          "%.1e, shapes %.1e; shift %.3g\n",
          floating ? "floating" : "held", 1e3 * wall, wanted, worst_value, worst_shape,
          alone.shift);
      EXPECT_LT(worst_value, 1e-12);
      EXPECT_LT(worst_shape, 1e-9);
    }
  }
  EXPECT_EQ(cache.orderings(), 2);        // one per topology
  EXPECT_EQ(cache.ordering_reuses(), 2);  // the second design of each
  EXPECT_EQ(cache.analyses(), 0);         // and no Jacobian structure
}

// ---- The exact frequencies of a frame of prismatic members (the dynamic stiffness method) ----
// Each member is an Euler-Bernoulli beam with the rotary inertia of its sections (a Rayleigh beam:
// EI v'''' + rho I w^2 v'' - rho S w^2 v = 0 at circular frequency w), an axial rod and a torsion
// rod (polar mass moment rho (Iy + Iz)): the continuum the model's lumped segments converge to
// (each generated body carries rho S a and rho I a). The exact harmonic end forces of a member,
// K(w) d, follow from the closed-form solutions; the frame's natural frequencies are where the
// assembled K(w) of the free joints is singular. Counting them: by Wittrick and Williams the
// number of natural frequencies below w is J0(w) + s(K(w)), s the number of negative eigenvalues
// and J0 that of the members clamped at both ends (a pole of K(w), where s falls by one as J0
// rises by one), so every rise of s is a natural frequency.
struct ExactMember {
  double l, ea, gj, eiy, eiz, rho_s, rho_iy, rho_iz;
  Eigen::Matrix3d axes;  // rows: the member's x (along it), y, z in global axes
  int joint1, joint2;    // free joints, -1: clamped
};

// Dofs (v(0), v'(0), v(l), v'(l)) of a Rayleigh beam; the end forces are the energy's
// conjugates: -(EI v''' + rho I w^2 v') and EI v'' at l, their negatives at 0.
Eigen::Matrix4d rayleigh_beam(double ei, double rho_s, double rho_i, double l, double w) {
  const double root = std::sqrt(std::pow(rho_i * w * w, 2) + 4 * ei * rho_s * w * w);
  const double a = std::sqrt((rho_i * w * w + root) / (2 * ei));   // cos, sin
  const double b = std::sqrt((-rho_i * w * w + root) / (2 * ei));  // cosh, sinh
  const auto derivatives = [&](double x) {  // rows: derivatives 0..3 of the four solutions
    const double c = std::cos(a * x), s = std::sin(a * x), ch = std::cosh(b * x),
                 sh = std::sinh(b * x);
    Eigen::Matrix4d f;
    f << c, s, ch, sh, -a * s, a * c, b * sh, b * ch, -a * a * c, -a * a * s, b * b * ch,
        b * b * sh, a * a * a * s, -a * a * a * c, b * b * b * sh, b * b * b * ch;
    return f;
  };
  const Eigen::Matrix4d f0 = derivatives(0.0), fl = derivatives(l);
  Eigen::Matrix4d d, forces;
  d << f0.row(0), f0.row(1), fl.row(0), fl.row(1);
  forces << ei * f0.row(3) + rho_i * w * w * f0.row(1), -ei * f0.row(2),
      -(ei * fl.row(3) + rho_i * w * w * fl.row(1)), ei * fl.row(2);
  return forces * d.inverse();
}

// The rod stiffness u'' + inertia w^2 u = 0: dofs (u(0), u(l)).
Eigen::Matrix2d rod(double stiffness, double inertia, double l, double w) {
  const double k = w * std::sqrt(inertia / stiffness), c = stiffness * k / std::sin(k * l);
  Eigen::Matrix2d m;
  m << c * std::cos(k * l), -c, -c, c * std::cos(k * l);
  return m;
}

// K(w) of the free joints (6 dofs each: displacement, rotation; global axes).
Eigen::MatrixXd frame_dynamic_stiffness(const std::vector<ExactMember>& members, int joints,
                                        double w) {
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(6 * joints, 6 * joints);
  for (const ExactMember& m : members) {
    // Local dofs (u, v, w, tx, ty, tz) at end 1 then end 2; tz = v', ty = -w'.
    Eigen::Matrix<double, 12, 12> local = Eigen::Matrix<double, 12, 12>::Zero();
    const auto put = [&](const auto& sub, std::vector<int> dofs, std::vector<double> sign) {
      for (size_t i = 0; i < dofs.size(); ++i)
        for (size_t j = 0; j < dofs.size(); ++j)
          local(dofs[i], dofs[j]) += sign[i] * sign[j] * sub(i, j);
    };
    put(rod(m.ea, m.rho_s, m.l, w), {0, 6}, {1, 1});
    put(rod(m.gj, m.rho_iy + m.rho_iz, m.l, w), {3, 9}, {1, 1});
    put(rayleigh_beam(m.eiz, m.rho_s, m.rho_iz, m.l, w), {1, 5, 7, 11}, {1, 1, 1, 1});
    put(rayleigh_beam(m.eiy, m.rho_s, m.rho_iy, m.l, w), {2, 4, 8, 10}, {1, -1, 1, -1});
    Eigen::Matrix<double, 12, 12> t = Eigen::Matrix<double, 12, 12>::Zero();
    for (int b = 0; b < 4; ++b) t.block<3, 3>(3 * b, 3 * b) = m.axes;
    const Eigen::Matrix<double, 12, 12> global = t.transpose() * local * t;
    const int joint[2] = {m.joint1, m.joint2};
    for (int e1 = 0; e1 < 2; ++e1)
      for (int e2 = 0; e2 < 2; ++e2)
        if (joint[e1] >= 0 && joint[e2] >= 0)
          k.block<6, 6>(6 * joint[e1], 6 * joint[e2]) += global.block<6, 6>(6 * e1, 6 * e2);
  }
  return k;
}

// The lowest `count` natural frequencies [Hz], scanning in `step` and bisecting every rise of
// the negative eigenvalue count to 1e-13.
std::vector<double> exact_frequencies(const std::vector<ExactMember>& members, int joints,
                                      int count, double step) {
  const auto negatives = [&](double f) {
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(
        frame_dynamic_stiffness(members, joints, 2 * kPi * f), Eigen::EigenvaluesOnly);
    return static_cast<int>((eig.eigenvalues().array() < 0.0).count());
  };
  std::vector<double> found;
  std::function<void(double, double, int, int)> split = [&](double lo, double hi, int below,
                                                            int above) {
    if (above <= below) return;
    if (hi - lo <= 1e-13 * hi) {
      found.insert(found.end(), static_cast<size_t>(above - below), 0.5 * (lo + hi));
      return;
    }
    const double mid = 0.5 * (lo + hi);
    const int at = negatives(mid);
    split(lo, mid, below, at);
    split(mid, hi, at, above);
  };
  double f = 0.5 * step;
  int s = negatives(f);
  while (static_cast<int>(found.size()) < count && f < 1e4) {
    const int next = negatives(f + step);
    split(f, f + step, s, next);
    f += step;
    s = next;
  }
  found.resize(static_cast<size_t>(count));
  return found;
}

// The portal frame converges to its exact frequencies at order 2 in the segment length (the
// lumped mass), and the Richardson extrapolation of 32 and 64 segments agrees with them to 1e-6
// (measured: 5e-7 at worst, the fifth mode; 64 and 128 segments: 3e-8): the frequencies the
// comparison with CalculiX (scripts/bench_modal_vs_calculix) is checked against. Exact: 3.724124,
// 5.913605, 7.109569, 17.40156, 19.99353, 37.82900 Hz; 32 segments are 1.1e-4 to 1.6e-3 below.
TEST(Modal, PortalFrameConvergesToItsExactFrequencies) {
  const double e = 2.1e11, g = 8.0769e10, rho = 7850, b = 0.06, t = 0.004;
  const double area = b * b - (b - 2 * t) * (b - 2 * t);
  const double i = (std::pow(b, 4) - std::pow(b - 2 * t, 4)) / 12;
  const double j = 4 * std::pow(b - t, 4) * t / (4 * (b - t));  // Bredt (docs/model.md)
  Eigen::Matrix3d column, girder;
  column << 0, 0, 1, 1, 0, 0, 0, 1, 0;   // x up, y = global x (point 3), z = global y
  girder << 1, 0, 0, 0, 0, 1, 0, -1, 0;  // x along, y = global z (point 3), z = -global y
  const auto member = [&](double l, const Eigen::Matrix3d& axes, int j1, int j2) {
    return ExactMember{l,       e * area, g * j, e * i, e * i, rho * area,
                       rho * i, rho * i,  axes,  j1,    j2};
  };
  const std::vector<ExactMember> frame = {member(3, column, -1, 0), member(3, column, -1, 1),
                                          member(4, girder, 0, 1)};
  const int wanted = 6;
  const std::vector<double> exact = exact_frequencies(frame, 2, wanted, 0.02);
  ASSERT_EQ(exact.size(), 6u);
  std::map<int, std::vector<double>> f;
  for (int n : {16, 32, 64}) {
    const Model model = testing::scene_from_json(portal_frame(n));
    Data data(model);
    ModalOptions options;
    options.modes = wanted;
    const ModalResult r = solve_modal(model, options, data);
    ASSERT_TRUE(r.ok) << r.message;
    for (int k = 1; k <= wanted; ++k) f[n].push_back(elastic_mode(r, k)->frequency_hz);
  }
  double worst = 0;
  for (size_t k = 0; k < exact.size(); ++k) {
    const double e16 = f[16][k] / exact[k] - 1, e32 = f[32][k] / exact[k] - 1,
                 e64 = f[64][k] / exact[k] - 1;
    const double extrapolated = (4 * f[64][k] - f[32][k]) / 3 / exact[k] - 1;
    std::printf(
        "mode %zu: exact %.10f Hz; 32 segments %+.2e, 64 %+.2e (order %.3f, %.3f); "
        "extrapolated %+.1e\n",
        k + 1, exact[k], e32, e64, std::log2(e16 / e32), std::log2(e32 / e64), extrapolated);
    EXPECT_LT(e32, 0.0) << k;  // lumped mass: below
    EXPECT_GT(e32, -2e-3) << k;
    EXPECT_NEAR(std::log2(e32 / e64), 2.0, 0.01) << k;
    worst = std::max(worst, std::abs(extrapolated));
  }
  EXPECT_LT(worst, 1e-6);
}

}  // namespace
}  // namespace beamrail
