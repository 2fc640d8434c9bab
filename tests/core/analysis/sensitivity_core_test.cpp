// The pieces of the design sensitivities in core (core/analysis/sensitivity.hpp,
// core/model/generalized.hpp): products with K and M from the tangent's blocks equal the
// assembled matrices', a state carried to another model of the same scene gives the same forces
// when the model is the same, and an equilibrium without unique du/dp (a free mechanism) says so.
#include <gtest/gtest.h>

#include <Eigen/Dense>

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
  EXPECT_EQ(e.state_derivative({&model, &model, 1e-6}).size(), 0);
}

}  // namespace
}  // namespace beamrail
