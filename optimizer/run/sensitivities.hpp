// Design sensitivities of a study's responses (docs/study_files.md "Sensitivities", docs/model.md
// "Design sensitivities"): the derivative of every response of a design with respect to every
// design variable, from the design's converged results (core/analysis/sensitivity.hpp) and, per
// variable, the design's model along it: the scene built on hyper-dual numbers with the variable's
// numbers seeded (load_dual_scene: forward-mode automatic differentiation through the scene ->
// model build), or, for a variable that addresses more than the inline scene, from the studies
// built at x +- h. The derivatives of buckling factors still difference the models of the studies
// at x +- h. No analysis is run again.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "optimizer/run/evaluation.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {

struct ResponseSensitivities {
  bool ok = false;
  // Why there are none: a response without an exact derivative (a transient's peak, a mode of a
  // non-symmetric problem), an equilibrium that does not depend smoothly on the design (a free
  // mechanism), a variable that changes the scene's topology.
  std::string message;
  Eigen::MatrixXd jacobian;           // responses x variables (NaN for a response not computed)
  std::vector<std::string> warnings;  // a response on or near a crossing of modes, ...
};

// The step of variable value x along which the models are differenced: relative to the value's
// magnitude, or to `scale` (the variable's range, or 1) when the value is 0.
double sensitivity_step(double x, double scale);

// What one variable's derivatives are taken from: the design's model along it (directions, when
// the scene could be built on hyper-dual numbers) and the studies at x + h e_j and x - h e_j
// (plus, minus: needed without a direction, and by buckling factors).
struct VariableStep {
  const DualModel* direction = nullptr;
  const Study* plus = nullptr;
  const Study* minus = nullptr;
  double h = 0.0;
};

// The sensitivities of `design` (evaluated in `ev` with EvaluationOptions::keep_states), one
// VariableStep per variable.
ResponseSensitivities response_sensitivities(const Study& design, const Evaluation& ev,
                                             const std::vector<VariableStep>& steps);

}  // namespace beamrail
