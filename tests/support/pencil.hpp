// K (the symmetric part of the stiffness) and M of a model at its initial state, dense: the
// pencil K x = w^2 M x of the dense eigensolver tests and benchmarks.
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "core/model/data.hpp"
#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"

namespace beamrail::testing {

struct Pencil {
  Eigen::MatrixXd k, m;
};

inline Pencil pencil_at_rest(const Model& model) {
  Data data(model);
  std::vector<double> y(static_cast<size_t>(model.n_states));
  initial_state(model, y.data());
  set_state(model, data, y.data());
  compute_wrenches(model, data, 0.0);
  compute_tangent(model, data, 0.0, false);
  const Eigen::MatrixXd s = -Eigen::MatrixXd(stiffness_matrix(model, data));
  return {0.5 * (s + s.transpose()), Eigen::MatrixXd(mass_matrix(model, data))};
}

}  // namespace beamrail::testing
