// The pieces of the design sensitivities in core (core/analysis/sensitivity.hpp,
// core/model/generalized.hpp): products with K and M from the tangent's blocks equal the
// assembled matrices', a state carried to another model of the same scene gives the same forces
// when the model is the same, an equilibrium without unique du/dp (a free mechanism) says so, and
// the generalized forces on hyper-dual numbers are the analyses' forces, their closed-form tangent
// and, for rigidities or masses scaled by a factor, the closed-form derivatives.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/analysis/sensitivity.hpp"
#include "core/analysis/static_analysis.hpp"
#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"
#include "tests/support/scene_builder.hpp"

namespace beamrail {
namespace {

// Three bodies on beams off the axes, under a load, turned by a static solve.
Model frame() {
  testing::Scene s;
  s.material("steel", 2.1e11, 8.1e10).square("sq", 0.01);
  s.body("a", 1.0, Vec3(1e-3, 2e-3, 3e-3), Vec3(0.5, 0.1, 0.0));
  s.body("b", 2.0, Vec3(2e-3, 2e-3, 2e-3), Vec3(1.0, 0.3, 0.2));
  s.beam("ga", "ground", "a", Vec3(0, 0, 0), Vec3(0.5, 0.1, 0.0), "steel", "sq");
  s.beam("ab", "a", "b", Vec3(0.5, 0.1, 0.0), Vec3(1.0, 0.3, 0.2), "steel", "sq");
  s.force("b", Vec3(3, -40, 25));
  return s.model();
}

TEST(SensitivityCore, BlockProductsEqualTheAssembledMatrices) {
  const Model model = frame();
  Data data(model);
  ASSERT_TRUE(solve_static(model, {}, data).ok);
  compute_wrenches(model, data, 0.0);
  compute_tangent(model, data, 0.0, false);
  const Eigen::MatrixXd x = Eigen::MatrixXd::Random(model.n_dofs, 3);
  const Eigen::MatrixXd k = Eigen::MatrixXd(
      symmetric_stiffness(model, data, Eigen::VectorXd::Ones(model.n_dofs), nullptr));
  const Eigen::MatrixXd m = Eigen::MatrixXd(mass_matrix(model, data));
  EXPECT_LT((symmetric_stiffness_product(model, data, x) - k * x).norm(), 1e-12 * (k * x).norm());
  EXPECT_LT((mass_product(model, data, x) - m * x).norm(), 1e-14 * (m * x).norm());
}

TEST(SensitivityCore, AStateCarriedToTheSameModelGivesTheSameForces) {
  const Model model = frame();
  Data data(model);
  ASSERT_TRUE(solve_static(model, {}, data).ok);
  Data copy = moved_state(model, data, model, {});
  compute_wrenches(model, data, 0.0);
  compute_wrenches(model, copy, 0.0);
  for (size_t i = 0; i < model.bodies.size(); ++i)
    EXPECT_LT((data.wrench[i] - copy.wrench[i]).norm(), 1e-12) << i;
}

TEST(SensitivityCore, AFreeMechanismHasNoStateDerivative) {
  testing::Scene s;
  s.material("steel", 2.1e11, 8.1e10).square("sq", 0.01);
  s.body("a", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(0, 0, 0));
  s.body("b", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(1, 0, 0));
  s.beam("ab", "a", "b", Vec3(0, 0, 0), Vec3(1, 0, 0), "steel", "sq");
  const Model model = s.model();
  Data data(model);
  const EquilibriumSensitivity e(model, data, 0.0);
  EXPECT_NE(e.failure().find("singular"), std::string::npos) << e.failure();
  const DualModel fixed = design_direction(model, model, model, 1e-6);
  EXPECT_EQ(e.state_derivative({&fixed}).size(), 0);
}

}  // namespace
}  // namespace beamrail

namespace beamrail {
namespace {

using HVector = Eigen::Matrix<HyperDual, Eigen::Dynamic, 1>;

Eigen::VectorXd part(const HVector& w, double HyperDual::*member) {
  Eigen::VectorXd out(w.size());
  for (Eigen::Index r = 0; r < w.size(); ++r) out(r) = w(r).*member;
  return out;
}

// The model with every element's rigidities (or every body's mass and inertia) times `factor`.
Model scaled(Model m, double factor, bool stiffness) {
  if (stiffness) {
    for (Beam& e : m.beams) {
      e.ea *= factor, e.gj *= factor, e.eiy *= factor, e.eiz *= factor;
    }
  } else {
    for (Body& b : m.bodies) {
      b.mass *= factor;
      b.inertia *= factor;
    }
  }
  return m;
}

TEST(SensitivityCore, HyperDualForcesAreTheAnalysesForcesAndTheirTangent) {
  const Model model = frame();
  Data equilibrium(model);
  ASSERT_TRUE(solve_static(model, {}, equilibrium).ok);
  // Off the equilibrium, where the forces are not zero.
  Data data = moved_state(model, equilibrium, model, 1e-3 * Eigen::VectorXd::Random(model.n_dofs));
  const DualModel fixed = design_direction(model, model, model, 1e-3);
  const Eigen::VectorXd phi = Eigen::VectorXd::Random(model.n_dofs);
  const HVector w = dual_generalized_forces(model, data, fixed, {}, phi, 0.0, 1.0);
  compute_wrenches(model, data, 0.0);
  compute_tangent(model, data, 0.0, false);
  const Eigen::VectorXd forces = wrench_vector(model, data);
  const Eigen::VectorXd s_phi = stiffness_matrix(model, data) * phi;  // dW/du phi, closed form
  EXPECT_LT((part(w, &HyperDual::v) - forces).norm(), 1e-13 * forces.norm());
  EXPECT_LT((part(w, &HyperDual::a) - s_phi).norm(), 1e-11 * s_phi.norm());
  EXPECT_EQ(part(w, &HyperDual::b).norm(), 0.0);
  EXPECT_EQ(part(w, &HyperDual::ab).norm(), 0.0);
}

// Rigidities scaled by s: at a fixed state the elastic forces and their tangent are linear in s, so
// their derivatives at s = 1 are the forces and the tangent themselves, and every eigenvalue of the
// unloaded structure is s lambda: d lambda/ds = lambda. Masses scaled by s: d lambda/ds = -lambda.
// The model's derivatives are exact here (central differences of numbers linear in s).
TEST(SensitivityCore, ScaledRigiditiesAndMassesHaveTheirClosedFormDerivatives) {
  const Model loaded = frame();
  Data data(loaded);
  ASSERT_TRUE(solve_static(loaded, {}, data).ok);
  const Model model = with_loads(
      loaded, [](const Load&) { return false; }, false);
  const double h = 0.25;
  const Model stiffer = scaled(model, 1 + h, true), softer = scaled(model, 1 - h, true);
  const DualModel rigidity = design_direction(model, stiffer, softer, h);
  const Eigen::VectorXd phi = Eigen::VectorXd::Random(model.n_dofs);
  const HVector w = dual_generalized_forces(model, data, rigidity, {}, phi, 0.0, 1.0);
  compute_wrenches(model, data, 0.0);
  compute_tangent(model, data, 0.0, false);
  const Eigen::VectorXd forces = wrench_vector(model, data);
  const Eigen::VectorXd s_phi = stiffness_matrix(model, data) * phi;
  EXPECT_LT((part(w, &HyperDual::b) - forces).norm(), 1e-12 * forces.norm());
  EXPECT_LT((part(w, &HyperDual::ab) - s_phi).norm(), 1e-11 * s_phi.norm());

  // The modes of the unloaded structure, M-normalized.
  Data rest(model);
  compute_wrenches(model, rest, 0.0);
  compute_tangent(model, rest, 0.0, false);
  const Eigen::MatrixXd k = Eigen::MatrixXd(
      symmetric_stiffness(model, rest, Eigen::VectorXd::Ones(model.n_dofs), nullptr));
  const Eigen::MatrixXd m = Eigen::MatrixXd(mass_matrix(model, rest));
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(k, m);
  const std::vector<double> lambdas(eig.eigenvalues().data(),
                                    eig.eigenvalues().data() + eig.eigenvalues().size());
  const EigenvalueDerivatives by_rigidity = eigenvalue_derivatives(
      model, rest, {&rigidity}, {}, 0.0, 1.0, lambdas, eig.eigenvectors(), true);
  const Model heavier = scaled(model, 1 + h, false), lighter = scaled(model, 1 - h, false);
  const DualModel mass = design_direction(model, heavier, lighter, h);
  const EigenvalueDerivatives by_mass =
      eigenvalue_derivatives(model, rest, {&mass}, {}, 0.0, 1.0, lambdas, eig.eigenvectors(), true);
  double worst = 0.0;
  for (size_t i = 0; i < lambdas.size(); ++i) {
    worst = std::max({worst, std::abs(by_rigidity.values[i] / lambdas[i] - 1.0),
                      std::abs(by_mass.values[i] / lambdas[i] + 1.0)});
  }
  std::printf("%zu eigenvalues: d lambda/ds within %.1e of lambda (rigidities), -lambda (masses)\n",
              lambdas.size(), worst);
  EXPECT_LT(worst, 1e-11);
}

TEST(SensitivityCore, AModelAlongNoDirectionHasZeroDerivativesInfiniteTravelIncluded) {
  testing::Scene s;
  s.material("steel", 2.1e11, 8.1e10).square("sq", 0.01);
  s.body("carriage", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(0.5, 0, 0));
  s.rail("r", "prismatic", "ground", "carriage", Vec3(0, 0, 0), Vec3(0.5, 0, 0), "steel", "sq");
  const Model model = s.model();
  ASSERT_FALSE(std::isfinite(model.rails[0].travel_max));
  const DualModel d = design_direction(model, model, model, 1e-4);
  EXPECT_EQ(d.rails[0].travel_max.v, model.rails[0].travel_max);
  EXPECT_EQ(d.rails[0].travel_max.b, 0.0);
  EXPECT_EQ(d.rails[0].ends.length.v, model.rails[0].ends.length);
  EXPECT_EQ(d.bodies[1].mass.b, 0.0);
}

}  // namespace
}  // namespace beamrail
