// The equations of motion as SUNDIALS sees them: right-hand side, exact Jacobian (dense or sparse
// CSC with a structure computed once per model), and the quaternion projection. Callbacks never
// throw: an exception is recorded in the context and reported as an unrecoverable failure.
#pragma once

#include <nvector/nvector_serial.h>
#include <sundials/sundials_matrix.h>

#include <chrono>
#include <string>
#include <vector>

#include "core/model/data.hpp"
#include "core/model/dynamics.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// Structure of the sparse state Jacobian: per pattern block of 13 x 13, the entries that can be
// non-zero (dc/dt = v, dq/dt depends on q and w only, accelerations on everything coupled), in
// compressed sparse columns with sorted row indices.
struct JacobianPattern {
  std::vector<long> column_starts;  // n_states + 1
  std::vector<long> rows;           // nnz
  // Position in the value array of entry (r, s) of pattern block b: positions[b * 169 + 13 r + s],
  // -1 when the entry is structurally zero.
  std::vector<long> positions;
  long nnz() const { return static_cast<long>(rows.size()); }
};

JacobianPattern make_jacobian_pattern(const Model& model);

struct OdeContext {
  OdeContext(const Model& m, Data& d) : model(m), data(d) {}
  const Model& model;
  Data& data;
  std::vector<Mat13> blocks;
  JacobianPattern pattern;     // filled when the sparse solver is used
  std::string callback_error;  // an exception caught inside a callback
  // Wall-clock budget: past this moment the right-hand side fails unrecoverably.
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
  bool timed_out = false;
};

// SUNDIALS callbacks; user_data is an OdeContext*.
int ode_rhs(double t, N_Vector y, N_Vector ydot, void* user_data);
int ode_dense_jacobian(double t, N_Vector y, N_Vector fy, SUNMatrix jac, void* user_data, N_Vector,
                       N_Vector, N_Vector);
int ode_sparse_jacobian(double t, N_Vector y, N_Vector fy, SUNMatrix jac, void* user_data, N_Vector,
                        N_Vector, N_Vector);
// CVODE projection onto |q| = 1 (corrections and error estimate).
int ode_project(double t, N_Vector ycur, N_Vector corr, double eps, N_Vector err, void* user_data);
// After each step of ARKODE methods, which have no projection: q <- q / |q|.
int ode_normalize(double t, N_Vector y, void* user_data);

}  // namespace beamrail
