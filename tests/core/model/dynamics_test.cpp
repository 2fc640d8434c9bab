// The exact state Jacobian of the equations of motion against central finite differences.
#include "core/model/dynamics.hpp"

#include <gtest/gtest.h>

#include <cstdio>

#include "tests/support/random_elements.hpp"
#include "tests/support/scenes.hpp"

namespace beamrail {
namespace {

// Three free bodies and ground joined by beams of both formulations and both rail types, with
// damping, loads at points, gravity, and rotated bodies.
const char* kScene = R"({
  "gravity": [0.3, -9.81, 1.2],
  "materials": {"steel": {"E": 2.1e11, "G": 8.1e10, "density": 7850}},
  "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.012},
               "rod": {"shape": "circle", "diameter": 0.015}},
  "bodies": [
    {"name": "a", "mass": 2.0, "inertia": [0.01, 0.02, 0.025], "position": [1, 0, 0],
     "orientation": [0.9238795325112867, 0.0, 0.3826834323650898, 0.0],
     "velocity": [0.1, 0.2, -0.1], "angular_velocity": [1, -2, 3]},
    {"name": "b", "mass": 1.5, "inertia": [0.02, 0.01, 0.02, 0.001, -0.002, 0.0005],
     "position": [1.5, 0.5, 0.2], "velocity": [0, -0.3, 0.2], "angular_velocity": [0.5, 0.2, -1]},
    {"name": "c", "mass": 0.7, "inertia": [0.003, 0.004, 0.005], "position": [1.2, -0.4, 0.3],
     "orientation": [0.5, 0.5, 0.5, 0.5]}
  ],
  "beams": [
    {"name": "root", "body1": "ground", "body2": "a", "point1": [0, 0, 0], "point2": [0.9, 0, 0],
     "point3": [0, 1, 0], "material": "steel", "section": "sq", "damping": 1e-4},
    {"name": "ab", "body1": "a", "body2": "b", "point1": [1.1, 0.1, 0], "point2": [1.4, 0.45, 0.2],
     "point3": [1.1, 0.1, 1], "material": "steel", "section": "rod", "formulation": "paper",
     "damping": 2e-4}
  ],
  "rails": [
    {"name": "ac", "type": "prismatic", "body1": "a", "body2": "c", "point1": [1.0, -0.1, 0.1],
     "point2": [1.2, -0.35, 0.3], "point3": [1.0, 1, 0.1], "material": "steel", "section": "rod",
     "damping": 1e-4},
    {"name": "bc", "type": "cylindrical", "body1": "b", "body2": "c", "point1": [1.5, 0.3, 0.2],
     "point2": [1.25, -0.3, 0.3], "point3": [1.5, 0.3, 1.2], "material": "steel", "section": "sq",
     "formulation": "paper"}
  ],
  "loads": [
    {"type": "force", "body": "b", "point": [1.6, 0.5, 0.3], "value": [10, -5, 3]},
    {"type": "torque", "body": "c", "value": [0.5, 0.1, -0.2]}
  ]
})";

// The worst row-relative difference between the exact state Jacobian and central differences
// of the state derivative, at the scene's initial state perturbed (positions, orientations, the
// quaternions left slightly off unit norm).
double jacobian_difference(const Model& model) {
  Data data(model);
  const int n = model.n_states;
  Eigen::VectorXd y(n);
  initial_state(model, y.data());
  // Deform: perturb positions and orientations, and leave the quaternions slightly off unit norm.
  testing::Random rng(5);
  for (int k = 0; k < model.n_free(); ++k) {
    y.segment<3>(13 * k) += rng.vec3(2e-3);
    y.segment<4>(13 * k + 3) +=
        Vec4(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)) * 1e-2;
  }
  const double t = 0.3;
  std::vector<Mat13> blocks;
  state_jacobian_blocks(model, data, t, y.data(), blocks);
  Eigen::MatrixXd exact(n, n);
  scatter_dense(model, blocks, exact.data(), n);

  Eigen::MatrixXd fd(n, n);
  Eigen::VectorXd fp(n), fm(n);
  for (int j = 0; j < n; ++j) {
    const double h = 1e-6 * std::max(1.0, std::abs(y(j)));
    Eigen::VectorXd yp = y, ym = y;
    yp(j) += h, ym(j) -= h;
    state_derivative(model, data, t, yp.data(), fp.data());
    state_derivative(model, data, t, ym.data(), fm.data());
    fd.col(j) = (fp - fm) / (2 * h);
  }
  // Compare block-row by block-row, relative to the largest entry of that state's row group.
  double worst = 0.0;
  for (int r = 0; r < n; ++r) {
    const double scale = std::max(exact.row(r).cwiseAbs().maxCoeff(), 1e-12);
    worst = std::max(worst, (exact.row(r) - fd.row(r)).cwiseAbs().maxCoeff() / scale);
  }
  return worst;
}

TEST(Dynamics, ExactJacobianMatchesCentralDifferences) {
  const Model model = testing::scene_from_json(kScene);
  ASSERT_EQ(model.n_free(), 3);
  const double worst = jacobian_difference(model);
  std::printf("state Jacobian: worst row-relative difference to central FD = %.2e\n", worst);
  EXPECT_LT(worst, 1e-6);
}

// Joints of the three kinds between spinning bodies, a damped rod between them.
const char* kJointScene = R"({
  "gravity": [0, -9.81, 0],
  "materials": {"soft": {"E": 2.1e9, "G": 0.8e9, "density": 1000}},
  "sections": {"rod": {"shape": "circle", "diameter": 0.02}},
  "bodies": [
    {"name": "arm", "mass": 1.0, "inertia": [1e-3, 2e-3, 3e-3], "position": [0.1, 0, 0],
     "velocity": [0, 0.8, 0], "angular_velocity": [0.3, -0.2, 8]},
    {"name": "tip", "mass": 0.1, "inertia": [1e-5, 2e-5, 1.5e-5], "position": [0.5, 0, 0],
     "velocity": [0, 4, 0], "angular_velocity": [0, 0.5, 8]},
    {"name": "ball", "mass": 0.3, "inertia": [1e-4, 1e-4, 2e-4], "position": [0.6, 0.05, 0.02],
     "orientation": [0.5, 0.5, 0.5, 0.5], "angular_velocity": [2, 1, -3]},
    {"name": "weight", "mass": 0.2, "inertia": [1e-4, 1.2e-4, 0.8e-4], "position": [0.1, -0.1, 0]}
  ],
  "beams": [
    {"name": "rod", "body1": "arm", "body2": "tip", "point1": [0.1, 0, 0], "point2": [0.5, 0, 0],
     "point3": [0.1, 1, 0], "material": "soft", "section": "rod", "damping": 1e-4}
  ],
  "joints": [
    {"name": "pin", "type": "revolute", "body1": "ground", "body2": "arm", "point": [0, 0, 0],
     "axis": [0, 0, 1]},
    {"name": "knuckle", "type": "spherical", "body1": "tip", "body2": "ball",
     "point": [0.55, 0.02, 0.01]},
    {"name": "weld", "type": "fixed", "body1": "arm", "body2": "weight", "point": [0.1, -0.05, 0]}
  ]
})";

TEST(Dynamics, ExactJacobianOfJointsMatchesCentralDifferences) {
  const Model model = testing::scene_from_json(kJointScene);
  ASSERT_EQ(model.n_free(), 4);
  const double worst = jacobian_difference(model);
  std::printf("joints: worst row-relative difference to central FD = %.2e\n", worst);
  EXPECT_LT(worst, 1e-6);
}

}  // namespace
}  // namespace beamrail
