// Mode identification (core/analysis/modal_analysis.hpp, Mode::participation): participation
// factors and effective modal masses against the closed form of a two-mass axial chain, their
// completeness (over all modes they add up to the mass and inertia of the free bodies, computed
// here from the bodies themselves), momentum conservation of a floating scene's elastic modes,
// independence from where the scene sits, the dominant direction, and the modal assurance
// criterion.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "core/analysis/modal_analysis.hpp"
#include "tests/support/scene_builder.hpp"

namespace beamrail {
namespace {

using testing::Scene;

// ground -- k -- a -- k -- b along x: two equal masses m on two equal bars. Axially K = k [2, -1;
// -1, 1], M = m I: w^2 = (k/m) (3 -+ sqrt 5) / 2 with shapes (1, g) and (1, -1/g), g the golden
// ratio; the effective masses along x are m (1 + g)^2 / (1 + g^2) = 1.894 m and
// m (1 - 1/g)^2 / (1 + 1/g^2) = 0.106 m, together 2 m.
Scene axial_chain(const Vec3& offset) {
  Scene s;
  s.material("steel", 2.1e11, 8.1e10).square("sq", 0.02);
  s.body("a", 3.0, Vec3(1e-3, 1e-3, 1e-3), offset + Vec3(1, 0, 0));
  s.body("b", 3.0, Vec3(1e-3, 1e-3, 1e-3), offset + Vec3(2, 0, 0));
  s.beam("ga", "ground", "a", offset, offset + Vec3(1, 0, 0), "steel", "sq");
  s.beam("ab", "a", "b", offset + Vec3(1, 0, 0), offset + Vec3(2, 0, 0), "steel", "sq");
  return s;
}

// Every mode of a scene with `rigid` rigid-body modes.
ModalResult all_modes(const Model& model, int rigid = 0) {
  Data data(model);
  ModalOptions options;
  options.modes = model.n_dofs - rigid;
  options.solver = EigenSolverKind::kDense;
  return solve_modal(model, options, data);
}

TEST(ModalParticipation, TwoMassAxialChainMatchesTheClosedForm) {
  const Model model = axial_chain(Vec3::Zero()).model();
  const ModalResult r = all_modes(model);
  ASSERT_TRUE(r.ok) << r.message;
  const double m = 3.0, k = model.beams[0].ea / 1.0, g = (1 + std::sqrt(5.0)) / 2;
  const double w2[2] = {k / m * (3 - std::sqrt(5.0)) / 2, k / m * (3 + std::sqrt(5.0)) / 2};
  const double meff[2] = {m * (1 + g) * (1 + g) / (1 + g * g),
                          m * (1 - 1 / g) * (1 - 1 / g) / (1 + 1 / (g * g))};
  for (int i = 0; i < 2; ++i) {
    // The axial modes: the ones moving mass along x.
    const Mode* found = nullptr;
    for (const Mode& mode : r.modes)
      if (std::abs(mode.eigenvalue / w2[i] - 1) < 1e-6) found = &mode;
    ASSERT_NE(found, nullptr) << "axial mode " << i + 1;
    const double x = found->participation(0) * found->participation(0);
    std::printf("axial mode %d: effective mass x %.12f kg, closed form %.12f kg (%.1e)\n", i + 1, x,
                meff[i], std::abs(x / meff[i] - 1));
    EXPECT_NEAR(x / meff[i], 1.0, 1e-9);
    EXPECT_NEAR(effective_mass_fraction(*found, r)(0), meff[i] / (2 * m), 1e-9);
    EXPECT_EQ(dominant_direction(*found, r), 0);  // x
  }
  EXPECT_NEAR(r.rigid_mass(0), 2 * m, 1e-12);
}

// A 3-D scene of four bodies off every axis, held at two places: over all modes the effective
// masses add up to the totals, which are the bodies' mass and their inertia about the axes through
// their common centre of mass (parallel-axis theorem, computed here from the inputs).
TEST(ModalParticipation, EffectiveMassesOfAllModesAddUpToMassAndInertia) {
  Scene s;
  s.material("steel", 2.1e11, 8.1e10).square("sq", 0.012);
  const Vec3 c[4] = {Vec3(0.5, 0.2, 0.1), Vec3(0.9, 0.7, 0.3), Vec3(0.4, 1.1, 0.6),
                     Vec3(-0.2, 0.5, 0.9)};
  const double mass[4] = {1.5, 2.0, 0.7, 1.2};
  const Vec3 inertia[4] = {Vec3(2e-3, 3e-3, 4e-3), Vec3(4e-3, 3e-3, 2e-3), Vec3(2e-3, 2e-3, 2e-3),
                           Vec3(2e-3, 3e-3, 2.5e-3)};
  for (int i = 0; i < 4; ++i) s.body("b" + std::to_string(i), mass[i], inertia[i], c[i]);
  s.beam("g0", "ground", "b0", Vec3(0, 0, 0), c[0], "steel", "sq");
  for (int i = 0; i < 3; ++i)
    s.beam("m" + std::to_string(i), "b" + std::to_string(i), "b" + std::to_string(i + 1), c[i],
           c[i + 1], "steel", "sq");
  s.beam("g3", "ground", "b3", Vec3(-0.5, 0.5, 1.5), c[3], "steel", "sq");
  const Model model = s.model();
  const ModalResult r = all_modes(model);
  ASSERT_TRUE(r.ok) << r.message;
  ASSERT_EQ(static_cast<int>(r.modes.size()), model.n_dofs);

  double total = 0.0;
  Vec3 centre = Vec3::Zero();
  for (int i = 0; i < 4; ++i) total += mass[i], centre += mass[i] * c[i];
  centre /= total;
  EXPECT_NEAR((r.reference_point - centre).norm(), 0.0, 1e-14);
  Vec6 expected;
  expected.head<3>().setConstant(total);
  for (int d = 0; d < 3; ++d) {
    double j = 0.0;  // about the axis d through the centre of mass; bodies unrotated
    for (int i = 0; i < 4; ++i) {
      const Vec3 arm = c[i] - centre;
      j += inertia[i](d) + mass[i] * (arm.squaredNorm() - arm(d) * arm(d));
    }
    expected(3 + d) = j;
  }
  Vec6 sum = Vec6::Zero();
  for (const Mode& mode : r.modes) sum += mode.participation.cwiseProduct(mode.participation);
  for (int d = 0; d < 6; ++d) {
    std::printf("%s: sum of effective masses %.12g, total %.12g\n", kDirectionNames[d], sum(d),
                expected(d));
    EXPECT_NEAR(r.rigid_mass(d) / expected(d), 1.0, 1e-12);
    EXPECT_NEAR(sum(d) / expected(d), 1.0, 1e-9);
  }
}

// A floating pair: its rigid modes carry all of the mass, its elastic modes none (they conserve
// momentum: x^T M r = 0 for a translation r).
TEST(ModalParticipation, ElasticModesOfAFloatingSceneMoveNoMassOverall) {
  Scene s;
  s.material("steel", 2.1e11, 8.1e10).square("sq", 0.01);
  s.body("a", 2.0, Vec3(1e-3, 2e-3, 2e-3), Vec3(0.1, 0.3, -0.2));
  s.body("b", 3.0, Vec3(2e-3, 3e-3, 3e-3), Vec3(1.0, 0.5, 0.2));
  s.beam("ab", "a", "b", Vec3(0.1, 0.3, -0.2), Vec3(1.0, 0.5, 0.2), "steel", "sq");
  const Model model = s.model();
  const ModalResult r = all_modes(model, 6);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.rigid_modes, 6);
  Vec6 rigid = Vec6::Zero();
  double elastic = 0.0;
  for (const Mode& mode : r.modes) {
    const Vec6 f = effective_mass_fraction(mode, r);
    if (mode.kind == Mode::Kind::kRigid)
      rigid += f;
    else
      elastic = std::max(elastic, f.head<3>().maxCoeff());
  }
  std::printf("floating pair: largest translational fraction of an elastic mode %.2e\n", elastic);
  EXPECT_LT(elastic, 1e-12);
  for (int d = 0; d < 6; ++d) EXPECT_NEAR(rigid(d), 1.0, 1e-9) << kDirectionNames[d];
}

// Moving the whole scene 100 m away changes no participation: rotations are measured about the
// free bodies' centre of mass, not the origin.
TEST(ModalParticipation, DoNotDependOnWhereTheSceneSits) {
  const ModalResult near = all_modes(axial_chain(Vec3::Zero()).model());
  const ModalResult far = all_modes(axial_chain(Vec3(100, -70, 40)).model());
  ASSERT_TRUE(near.ok && far.ok);
  ASSERT_EQ(near.modes.size(), far.modes.size());
  for (size_t i = 0; i < near.modes.size(); ++i) {
    const Vec6 a = effective_mass_fraction(near.modes[i], near);
    const Vec6 b = effective_mass_fraction(far.modes[i], far);
    EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-6) << "mode " << i;
    EXPECT_EQ(dominant_direction(near.modes[i], near), dominant_direction(far.modes[i], far));
  }
}

// A tip body on a cantilever along x: its bending modes are dominated by y and z, its torsion by
// rx; MAC is 1 between a mode and itself (scaled), 0 between two modes.
TEST(ModalParticipation, DominantDirectionsAndModalAssurance) {
  Scene s;
  s.material("steel", 2.1e11, 8.1e10).custom("s", 1e-4, 2e-9, 1e-9, 4e-9);
  s.body("tip", 2.0, Vec3(1e-4, 1e-4, 1e-4), Vec3(1, 0, 0));
  s.beam("arm", "ground", "tip", Vec3(0, 0, 0), Vec3(1, 0, 0), "steel", "s");
  const Model model = s.model();
  Data data(model);
  ModalOptions options;
  options.modes = 6;
  options.keep_mass = true;
  const ModalResult r = solve_modal(model, options, data);
  ASSERT_TRUE(r.ok) << r.message;
  ASSERT_EQ(r.mass.rows(), model.n_dofs);
  // Iy = 1e-9 bends in z (about y) more softly than Iz = 4e-9 bends in y: z, then y. The next
  // mode is the torsion (GJ = 162 N m against rotary inertia 1e-4).
  EXPECT_EQ(dominant_direction(*elastic_mode(r, 1), r), 2);
  EXPECT_EQ(dominant_direction(*elastic_mode(r, 2), r), 1);
  EXPECT_EQ(dominant_direction(*elastic_mode(r, 3), r), 3);
  const Eigen::VectorXd& a = elastic_mode(r, 1)->shape;
  const Eigen::VectorXd& b = elastic_mode(r, 2)->shape;
  EXPECT_NEAR(modal_assurance(a, -3.0 * a, r.mass), 1.0, 1e-14);
  EXPECT_NEAR(modal_assurance(a, b, r.mass), 0.0, 1e-14);
  EXPECT_NEAR(modal_assurance(a, a + b, r.mass), 0.5, 1e-12);
}

}  // namespace
}  // namespace beamrail
