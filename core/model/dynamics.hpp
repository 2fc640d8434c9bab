// Rigid-body equations of motion of the free bodies (docs/model.md) as a first-order system
// dy/dt = f(t, y) with 13 states per free body, y_k = (u, q, v, w), u = c - position the
// displacement of the centre from the body's initial one (docs/model.md "Bodies"):
//   du/dt = v,  dq/dt = 1/2 q (x) (0, w),  m dv/dt = F,  J dw/dt = A^T M - w x (J w),
// and its exact Jacobian df/dy, assembled per 13 x 13 block from the element tangents.
#pragma once

#include <Eigen/Core>

#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

using Mat13 = Eigen::Matrix<double, kStatesPerBody, kStatesPerBody>;

// ydot = f(t, y); y and ydot have dim model.n_states. Leaves data at the state y.
void state_derivative(const Model& model, Data& data, double t, const double* y, double* ydot);

// The Jacobian df/dy at (t, y) as 13 x 13 blocks, one per model.pattern block (row free body,
// column free body), written to blocks (resized once to model.pattern.blocks.size()).
void state_jacobian_blocks(const Model& model, Data& data, double t, const double* y,
                           std::vector<Mat13>& blocks);

// Writes the blocks into a dense column-major n_states x n_states matrix with leading dim ld.
void scatter_dense(const Model& model, const std::vector<Mat13>& blocks, double* a, long ld);

// Normalizes every quaternion of y in place; returns the largest | |q| - 1 | found before.
double normalize_quaternions(const Model& model, double* y);

}  // namespace beamrail
