#include "core/analysis/ode_system.hpp"

#include <sunmatrix/sunmatrix_dense.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>

#include "core/analysis/deformation_check.hpp"

namespace beamrail {
namespace {

constexpr int kS = kStatesPerBody;

template <class F>
int guarded(OdeContext* c, F&& f) {
  try {
    return f();
  } catch (const std::exception& e) {
    c->callback_error = e.what();
  } catch (...) {
    c->callback_error = "unknown error";
  }
  return -1;
}

// A non-finite state or right-hand side at time t: recoverable (the integrator retries with a
// smaller step) until kNonFiniteLimit of them within one call of the integrator, then the end.
int non_finite(OdeContext* c, double t, const char* what) {
  if (++c->nonfinite_evaluations < kNonFiniteLimit) return 1;
  char when[32];
  std::snprintf(when, sizeof when, "%.9g", t);
  c->divergence = std::string("the ") + what + " became non-finite at t = " + when +
                  " s and smaller steps did not help (" + std::to_string(kNonFiniteLimit) +
                  " attempts): the motion diverged; check the loads (their size and time "
                  "functions), the masses and the stiffnesses";
  return -1;
}

// An element outside the range of its law at time t (core/analysis/deformation_check.hpp):
// recoverable (a trial state of the Newton iteration may overshoot; the integrator retries with a
// smaller step) until kNonFiniteLimit of them within one call of the integrator, then the end.
int out_of_range(OdeContext* c, double t) {
  char when[48];
  std::snprintf(when, sizeof when, "at t = %.9g s, ", t);
  c->out_of_range = when + element_out_of_range(c->model, c->data);
  c->out_of_range_t = t;
  if (++c->nonfinite_evaluations < kNonFiniteLimit) return 1;
  c->divergence = c->out_of_range;
  return -1;
}

}  // namespace

int ode_rhs(double t, N_Vector y, N_Vector ydot, void* user_data) {
  auto* c = static_cast<OdeContext*>(user_data);
  if (c->should_stop() || !c->divergence.empty()) return -1;
  return guarded(c, [&] {
    const double* s = N_VGetArrayPointer(y);
    double* f = N_VGetArrayPointer(ydot);
    const long n = c->model.n_states;
    for (long i = 0; i < n; ++i)
      if (!std::isfinite(s[i])) return non_finite(c, t, "state");
    state_derivative(c->model, c->data, c->force_time(t), s, f);
    for (long i = 0; i < n; ++i)
      if (!std::isfinite(f[i])) return non_finite(c, t, "forces");
    if (c->data.out_of_range) return out_of_range(c, t);
    return 0;
  });
}

int ode_dense_jacobian(double t, N_Vector y, N_Vector, SUNMatrix jac, void* user_data, N_Vector,
                       N_Vector, N_Vector) {
  auto* c = static_cast<OdeContext*>(user_data);
  return guarded(c, [&] {
    state_jacobian_blocks(c->model, c->data, c->force_time(t), N_VGetArrayPointer(y), c->blocks);
    scatter_dense(c->model, c->blocks, SUNDenseMatrix_Data(jac), SUNDenseMatrix_Rows(jac));
    const long n = c->model.n_states;
    const double* a = SUNDenseMatrix_Data(jac);
    for (long i = 0; i < n * n; ++i)
      if (!std::isfinite(a[i])) return 1;
    return 0;
  });
}

int ode_sparse_jacobian(double t, N_Vector y, N_Vector, SUNMatrix jac, void* user_data, N_Vector,
                        N_Vector, N_Vector) {
  auto* c = static_cast<OdeContext*>(user_data);
  return guarded(c, [&] {
    state_jacobian_blocks(c->model, c->data, c->force_time(t), N_VGetArrayPointer(y), c->blocks);
    const JacobianPattern& p = c->structure->pattern();
    sunindextype* starts = SUNSparseMatrix_IndexPointers(jac);
    sunindextype* rows = SUNSparseMatrix_IndexValues(jac);
    double* values = SUNSparseMatrix_Data(jac);
    std::copy(p.column_starts.begin(), p.column_starts.end(), starts);
    std::copy(p.rows.begin(), p.rows.end(), rows);
    for (size_t b = 0; b < c->blocks.size(); ++b) {
      const long* pos = p.positions.data() + b * kS * kS;
      const Mat13& m = c->blocks[b];
      for (int r = 0; r < kS; ++r)
        for (int s = 0; s < kS; ++s)
          if (pos[kS * r + s] >= 0) values[pos[kS * r + s]] = m(r, s);
    }
    for (long i = 0; i < p.nnz(); ++i)
      if (!std::isfinite(values[i])) return 1;
    return 0;
  });
}

int ode_project(double, N_Vector ycur, N_Vector corr, double, N_Vector err, void* user_data) {
  auto* c = static_cast<OdeContext*>(user_data);
  const double* y = N_VGetArrayPointer(ycur);
  double* dy = N_VGetArrayPointer(corr);
  double* e = err ? N_VGetArrayPointer(err) : nullptr;
  N_VConst(0.0, corr);
  for (int k = 0; k < c->model.n_free(); ++k) {
    const long o = kS * k + 3;
    const Vec4 q(y[o], y[o + 1], y[o + 2], y[o + 3]);
    const double norm = q.norm();
    if (!(norm > 0.0) || !std::isfinite(norm)) return 1;
    const Vec4 qn = q / norm;
    for (int j = 0; j < 4; ++j) dy[o + j] = qn(j) - q(j);
    if (e) {
      const Vec4 ev(e[o], e[o + 1], e[o + 2], e[o + 3]);
      const Vec4 pe = ev - qn * qn.dot(ev);
      for (int j = 0; j < 4; ++j) e[o + j] = pe(j);
    }
  }
  return 0;
}

int ode_normalize(double t, N_Vector y, void* user_data) {
  auto* c = static_cast<OdeContext*>(user_data);
  normalize_quaternions(c->model, N_VGetArrayPointer(y));
  c->accepted_t = t;
  if (c->step_taken) c->step_taken(t, N_VGetArrayPointer(y));
  return 0;
}

int ode_error_weights(N_Vector y, N_Vector weights, void* user_data) {
  return static_cast<OdeContext*>(user_data)->error_weights(y, weights);
}

}  // namespace beamrail
