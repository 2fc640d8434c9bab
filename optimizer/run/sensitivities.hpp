// Design sensitivities of a study's responses (docs/study_files.md "Sensitivities", docs/model.md
// "Design sensitivities"): the derivative of every response of a design with respect to every
// design variable, from the design's converged results (core/analysis/sensitivity.hpp) and, per
// variable, the design's model along it: the scene built on hyper-dual numbers with the variable's
// numbers seeded (load_dual_scene: forward-mode automatic differentiation through the scene ->
// model build). No analysis is run again. A variable that addresses more than the inline scene, or
// a number the build does not differentiate (a segment count, the segmentation target), has
// no exact derivative: the study says so (gradient algorithms then take "gradient": "fd").
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

// The sensitivities of `design` (evaluated in `ev` with EvaluationOptions::keep_states) along
// the design's models along each variable (load_dual_scene).
ResponseSensitivities response_sensitivities(const Study& design, const Evaluation& ev,
                                             const std::vector<DualModel>& directions);

}  // namespace beamrail
