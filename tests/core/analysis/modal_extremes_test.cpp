// Modal analysis where eigenvalue ratios mislead: fine meshes (a soft mode 1e-20 of the stiffest),
// wide stiffness ratios, a preloaded column near buckling, and scenes with rigid-body or mechanism
// modes. A mode is rigid when it deforms no element; a frequency the rounding of double precision
// cannot resolve fails the analysis instead of being reported.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "core/analysis/element_deformation.hpp"
#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/static_analysis.hpp"
#include "tests/support/scene_builder.hpp"

namespace beamrail {
namespace {

using testing::Scene;
constexpr double kE = 2.1e11, kG = 8.0769e10, kPi = std::numbers::pi;

ModalResult modes_of(const Model& model, int wanted, Data& data) {
  ModalOptions options;
  options.modes = wanted;
  return solve_modal(model, options, data);
}

ModalResult modes_of(const Model& model, int wanted) {
  Data data(model);
  return modes_of(model, wanted, data);
}

// A 1 m steel cantilever of 10 mm square section in `segments` segments with a 1 kg tip body
// (inertia 1e-4 kg m^2): the scene of the reports of lost modes.
Model tip_cantilever(int segments) {
  Scene s;
  s.material("steel", kE, kG, 7850).square("sq10", 0.01);
  s.body("tip", 1.0, Vec3(1e-4, 1e-4, 1e-4), Vec3(1, 0, 0));
  s.beam("arm", "ground", "tip", Vec3::Zero(), Vec3(1, 0, 0), "steel", "sq10");
  s.last_beam()["segments"] = segments;
  return s.model();
}

double peak_memory_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

// f1 of the tip cantilever converges as 1/N^2 from 10 to 3,000 segments; beyond, the stiffness
// terms of the 1e-5 m segments cancel below the mode's inertia forces in double precision, and
// the analysis says so instead of reporting a frequency. (It once reported 38.1 Hz at 1,000
// segments, 24,816 Hz at 10,000 and 13.5 MHz at 100,000: the true lowest modes had been called
// rigid by an eigenvalue ratio and dropped.)
TEST(ModalExtremes, FineMeshesKeepTheLowestModeOrSayTheyCannotResolveIt) {
  const double f100 = modes_of(tip_cantilever(100), 2).modes.at(0).frequency_hz;
  const double f200 = modes_of(tip_cantilever(200), 2).modes.at(0).frequency_hz;
  const double converged = f200 + (f200 - f100) / 3.0;  // Richardson, error ~ 1/N^2
  const double c = (f100 - converged) * 100.0 * 100.0;  // f(N) = converged + c / N^2
  std::printf("f1 converged (Richardson from 100 and 200 segments): %.10f Hz\n", converged);
  for (int n : {10, 300, 1000, 3000, 10000, 100000}) {
    const Model model = tip_cantilever(n);
    const auto start = std::chrono::steady_clock::now();
    const ModalResult r = modes_of(model, 2);
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!r.ok) {
      std::printf("N = %6d: not resolved (%.2f s, peak memory %.0f MiB): %s\n", n, wall,
                  peak_memory_mib(), r.message.c_str());
      EXPECT_GT(n, 3000) << r.message;
      EXPECT_NE(r.message.find("not resolved"), std::string::npos) << r.message;
      continue;
    }
    const Mode* mode = elastic_mode(r, 1);
    ASSERT_NE(mode, nullptr);
    const double expected = converged + c / (double(n) * n);
    const double error = std::abs(mode->frequency_hz / expected - 1);
    std::printf(
        "N = %6d: f1 = %.10f Hz, expected %.10f (error %.1e), noise %.1e, %zu warning(s), %.2f "
        "s, %s\n",
        n, mode->frequency_hz, expected, error, mode->noise, r.warnings.size(), wall,
        r.solver.c_str());
    EXPECT_EQ(r.rigid_modes, 0);
    EXPECT_EQ(r.warnings.empty(), mode->noise <= kModalNoiseWarning);
    // The documented resolution, kModalNoiseError x noise; at 10 segments the 1/N^2 model of the
    // discretization error is itself off by ~2e-6.
    if (n > 10) {
      EXPECT_LT(error, std::max(1e-7, kModalNoiseError * mode->noise)) << "N = " << n;
    }
  }
}

// Two beams in series, the second 1e8 times softer: the two lowest modes (the soft beam bending
// the tip body in y and in z) are found at their closed form, not dropped as rigid. (It once gave
// f1 = 0.0054 Hz instead of 3.65e-4 Hz.)
TEST(ModalExtremes, StiffnessRatioOfTenToTheEightKeepsTheSoftModes) {
  Scene s;
  s.material("steel", kE, kG).material("soft", kE * 1e-8, kG * 1e-8).square("sq10", 0.01);
  s.body("b1", 1.0, Vec3(1e-4, 1e-4, 1e-4), Vec3(1, 0, 0));
  s.body("b2", 1.0, Vec3(1e-4, 1e-4, 1e-4), Vec3(2, 0, 0));
  s.beam("stiff", "ground", "b1", Vec3::Zero(), Vec3(1, 0, 0), "steel", "sq10");
  s.beam("soft", "b1", "b2", Vec3(1, 0, 0), Vec3(2, 0, 0), "soft", "sq10");
  const Model model = s.model();
  const ModalResult r = modes_of(model, 4);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.rigid_modes, 0);
  // The soft beam with b1 held: K = EI [12/l^3, -6/l^2; -6/l^2, 4/l], M = diag(m, J). b1 moves
  // 1e-8 as much, which changes w^2 by ~1e-8.
  const double ei = kE * 1e-8 * std::pow(0.01, 4) / 12;
  Eigen::Matrix2d k, m;
  k << 12 * ei, -6 * ei, -6 * ei, 4 * ei;
  m << 1.0, 0.0, 0.0, 1e-4;
  const double w2 =
      Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix2d>(k, m).eigenvalues()(0);
  for (int i : {1, 2}) {
    const double error = std::abs(elastic_mode(r, i)->eigenvalue / w2 - 1);
    std::printf("mode %d: %.6e Hz, closed form %.6e Hz, w^2 error %.1e, deformation %.1e\n", i,
                elastic_mode(r, i)->frequency_hz, std::sqrt(w2) / (2 * kPi), error,
                elastic_mode(r, i)->deformation);
    EXPECT_LT(error, 1e-7);
  }
}

// A cantilever column of 1 m with a 1 kg tip body under an axial load P at 0.99 of its Euler
// load: the bending mode softens to w^2 = k(P) / m with the lateral tip stiffness
// k(P) = P / (tan(kL) / k - L), k = sqrt(P / EI) (massless inextensible column, tip free to
// turn). Its
// eigenvalue is ~1e-12 of the stiffest, yet it deforms the column: it stays elastic and
// converges with the segments. (A frame near its buckling load once had its softening mode
// called rigid from 80 segments on.)
TEST(ModalExtremes, PreloadedColumnNearBucklingKeepsItsSoftMode) {
  const double ei = kE * std::pow(0.01, 4) / 12, l = 1.0;
  const double p = 0.99 * kPi * kPi * ei / (4 * l * l);
  const double kk = std::sqrt(p / ei);
  const double w2 = p / (std::tan(kk * l) / kk - l) / 1.0;
  std::printf("P = %.6g N (0.99 of the Euler load); closed form f1 = %.8f Hz\n", p,
              std::sqrt(w2) / (2 * kPi));
  double previous = NAN;
  for (int n : {20, 40, 80, 160}) {
    Scene s;
    // A density of 1e-3 kg/m^3: segment masses ~1e-11 of the tip's. The section area is 1 m^2
    // so that the load shortens the column by only 2e-9 (a shortening of 2e-5, as a 10 mm steel
    // square would have, moves the buckling load by that much and w^2 by 100 times as much).
    s.material("steel", kE, kG, 1e-3).custom("sq10", 1.0, 1.41e-9, ei / kE, ei / kE);
    s.body("tip", 1.0, Vec3(1e-9, 1e-9, 1e-9), Vec3(0, l, 0));
    s.beam("column", "ground", "tip", Vec3::Zero(), Vec3(0, l, 0), "steel", "sq10");
    s.last_beam()["point3"] = testing::vec(1, 0, 0);
    s.last_beam()["segments"] = n;
    s.force("tip", Vec3(0, -p, 0));
    const Model model = s.model();
    Data data(model);
    const StaticResult equilibrium = solve_static(model, StaticOptions{}, data);
    ASSERT_TRUE(equilibrium.ok) << equilibrium.message;
    const ModalResult r = modes_of(model, 2, data);
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_EQ(r.rigid_modes, 0);
    const Mode* mode = elastic_mode(r, 1);
    ASSERT_NE(mode, nullptr);
    const double error = std::abs(mode->eigenvalue / w2 - 1);
    std::printf("N = %3d: f1 = %.8f Hz (w^2 error %.2e), deformation %.1e\n", n, mode->frequency_hz,
                error, mode->deformation);
    EXPECT_EQ(mode->kind, Mode::Kind::kElastic);
    if (!std::isnan(previous)) {  // converges towards the closed form as N grows
      const double order = std::log2(std::abs(previous / w2 - 1) / error);
      std::printf("  observed order %.2f\n", order);
      EXPECT_GT(order, 1.4);
      // Richardson from N / 2 and N: the 1/N^2 term removed.
      const double richardson = (4 * mode->eigenvalue - previous) / 3;
      std::printf("  Richardson w^2 error %.2e\n", std::abs(richardson / w2 - 1));
      if (n == 160) {
        EXPECT_LT(std::abs(richardson / w2 - 1), 1e-3);
      }
    }
    previous = mode->eigenvalue;
  }
}

// A free body has 6 rigid modes and no elastic one: asking for one fails, with the count. (It
// once returned no mode and f1 = nan with status ok.) A carriage on one prismatic rail has one
// mechanism mode (it slides) and 5 elastic ones: 5 can be had, 6 cannot.
TEST(ModalExtremes, FewerElasticModesThanAskedFails) {
  Scene free_body;
  free_body.body("block", 2.0, Vec3(1e-2, 2e-2, 3e-2), Vec3(0, 0, 0));
  const ModalResult none = modes_of(free_body.model(), 1);
  std::printf("free body, 1 mode asked: ok = %d, %d rigid: %s\n", none.ok, none.rigid_modes,
              none.message.c_str());
  EXPECT_FALSE(none.ok);
  EXPECT_EQ(none.rigid_modes, 6);
  EXPECT_NE(none.message.find("has none"), std::string::npos) << none.message;

  Scene carriage;
  carriage.material("steel", kE, kG).circle("rod", 0.02);
  carriage.body("carriage", 5.0, Vec3(0.03, 0.02, 0.02), Vec3(0.4, 0, 0));
  carriage.rail("guide", "prismatic", "ground", "carriage", Vec3::Zero(), Vec3(0.4, 0, 0), "steel",
                "rod");
  const Model model = carriage.model();
  const ModalResult five = modes_of(model, 5);
  ASSERT_TRUE(five.ok) << five.message;
  EXPECT_EQ(five.rigid_modes, 1);
  const ModalResult six = modes_of(model, 6);
  std::printf("carriage on one rail, 6 modes asked: ok = %d: %s\n", six.ok, six.message.c_str());
  EXPECT_FALSE(six.ok);
  EXPECT_NE(six.message.find("only 5"), std::string::npos) << six.message;
  // The mechanism mode slides the carriage along the rail and deforms nothing.
  for (const Mode& mode : five.modes)
    if (mode.kind == Mode::Kind::kRigid) {
      EXPECT_LT(mode.deformation, 1e-10);
      EXPECT_GT(std::abs(mode.shape(0)), 0.99 * mode.shape.head<3>().norm());
    }
}

// The deformation measure against hand-made motions: a rigid motion of a floating chain deforms
// nothing; bending one segment of N deforms ~1/N of the motion.
TEST(ModalExtremes, ElementDeformationTellsRigidFromElasticMotion) {
  Scene s;
  s.material("steel", kE, kG, 7850).square("sq10", 0.01);
  s.body("a", 1.0, Vec3(1e-4, 1e-4, 1e-4), Vec3(0, 0, 0));
  s.body("b", 1.0, Vec3(1e-4, 1e-4, 1e-4), Vec3(1, 0, 0));
  s.beam("ab", "a", "b", Vec3::Zero(), Vec3(1, 0, 0), "steel", "sq10");
  s.last_beam()["segments"] = 10;
  const Model model = s.model();
  const Data data(model);
  const ElementDeformation deformation(model, data);
  EXPECT_NEAR(deformation.length_scale(), 1.0, 1e-12);
  Eigen::VectorXd rigid(model.n_dofs), bend(model.n_dofs);
  const Vec3 v(0.3, -0.2, 0.7), w(0.1, 0.5, -0.4);
  for (int k = 0; k < model.n_free(); ++k) {
    const Vec3 c = centre(model, data, model.free_bodies[k]);
    rigid.segment<3>(6 * k) = v + w.cross(c);
    rigid.segment<3>(6 * k + 3) = w;
    // A parabola y = x^2 / 2 (curvature 1): slope x, rotation about z.
    bend.segment<3>(6 * k) = Vec3(0, 0.5 * c.x() * c.x(), 0);
    bend.segment<3>(6 * k + 3) = Vec3(0, 0, c.x());
  }
  const double r_rigid = deformation.ratio(rigid), r_bend = deformation.ratio(bend);
  std::printf("rigid motion: %.2e; uniform bending over 10 segments: %.3e\n", r_rigid, r_bend);
  EXPECT_LT(r_rigid, 1e-15);
  // Each segment turns by 0.1 rad relative to its neighbour and its far end lies l^2 / 2 off the
  // tangent of its near end; the largest motion is 0.5 m + 1 rad (length scale 1 m).
  EXPECT_NEAR(r_bend, (0.1 + 0.005) / 1.5, 1e-12);
}

// max_seconds stops a modal analysis between its phases and the eigensolver's operator
// applications: a 30,000-segment chain (about 2 s unbudgeted) stops after its first phase
// (assembling the symmetric part, ~0.4 s) under a 0.05 s budget. (Budgets once stopped transients
// only: static and modal designs of 1.3-2.1 s ran to the end under 0.2 s and were reported ok.)
TEST(ModalExtremes, TimeBudgetStopsTheAnalysis) {
  const Model model = tip_cantilever(30000);
  Data data(model);
  ModalOptions options;
  options.modes = 2;
  options.max_seconds = 0.05;
  const auto start = std::chrono::steady_clock::now();
  const ModalResult r = solve_modal(model, options, data);
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("30,000 segments in 0.05 s: ok = %d, timed out = %d, %.3f s: %s\n", r.ok, r.timed_out,
              wall, r.message.c_str());
  EXPECT_FALSE(r.ok);
  EXPECT_TRUE(r.timed_out);
  EXPECT_NE(r.message.find("time budget"), std::string::npos) << r.message;
}

}  // namespace
}  // namespace beamrail
