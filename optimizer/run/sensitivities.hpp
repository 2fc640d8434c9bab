// Design sensitivities of a study's responses (docs/study_files.md "Sensitivities", docs/model.md
// "Design sensitivities"): the derivative of every response of a design with respect to every
// design variable, from the design's converged results (core/analysis/sensitivity.hpp) and the
// studies built at x +- h along each variable (their models' partial derivatives; no analysis is
// run again).
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

// The sensitivities of `design` (evaluated in `ev` with EvaluationOptions::keep_states) from the
// studies at x + h_j e_j (plus[j]) and x - h_j e_j (minus[j]).
ResponseSensitivities response_sensitivities(const Study& design, const Evaluation& ev,
                                             const std::vector<const Study*>& plus,
                                             const std::vector<const Study*>& minus,
                                             const std::vector<double>& h);

}  // namespace beamrail
