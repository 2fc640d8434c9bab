#include "core/analysis/ode_system.hpp"

#include <sunmatrix/sunmatrix_dense.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <cmath>
#include <exception>

namespace beamrail {
namespace {

constexpr int kS = kStatesPerBody;

// Whether entry (r, s) of a 13 x 13 block can be non-zero.
bool structural(bool diagonal, int r, int s) {
  if (r >= 7) return true;  // accelerations depend on every coupled state
  if (!diagonal) return false;
  // dc/dt = v; the (zero) diagonal is stored too, so that SUNDIALS forms I - gamma J in place
  // (without it, SUNMatScaleAddI_Sparse rebuilds the matrix at every setup: 92 % of the run time
  // of a 1,000-body chain).
  if (r < 3) return s == r + 7 || s == r;
  return (s >= 3 && s <= 6) || s >= 10;  // dq/dt = q (x) (0, w) / 2
}

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

}  // namespace

JacobianPattern make_jacobian_pattern(const Model& model) {
  const long n = model.n_states;
  const auto& blocks = model.pattern.blocks;
  // Blocks by column body.
  std::vector<std::vector<int>> by_column(model.n_free());
  for (size_t b = 0; b < blocks.size(); ++b)
    by_column[blocks[b].col].push_back(static_cast<int>(b));
  for (auto& list : by_column)
    std::sort(list.begin(), list.end(),
              [&](int a, int b) { return blocks[a].row < blocks[b].row; });
  JacobianPattern p;
  p.positions.assign(blocks.size() * kS * kS, -1);
  p.column_starts.assign(n + 1, 0);
  for (long j = 0; j < n; ++j) {
    const int body = static_cast<int>(j / kS), s = static_cast<int>(j % kS);
    for (int b : by_column[body]) {
      const bool diagonal = blocks[b].row == blocks[b].col;
      for (int r = 0; r < kS; ++r) {
        if (!structural(diagonal, r, s)) continue;
        p.positions[static_cast<size_t>(b) * kS * kS + kS * r + s] =
            static_cast<long>(p.rows.size());
        p.rows.push_back(static_cast<long>(kS) * blocks[b].row + r);
      }
    }
    p.column_starts[j + 1] = static_cast<long>(p.rows.size());
  }
  return p;
}

int ode_rhs(double t, N_Vector y, N_Vector ydot, void* user_data) {
  auto* c = static_cast<OdeContext*>(user_data);
  if (std::chrono::steady_clock::now() > c->deadline) {
    c->timed_out = true;
    return -1;
  }
  return guarded(c, [&] {
    double* f = N_VGetArrayPointer(ydot);
    state_derivative(c->model, c->data, t, N_VGetArrayPointer(y), f);
    for (long i = 0; i < c->model.n_states; ++i)
      if (!std::isfinite(f[i])) return 1;  // recoverable: the integrator retries smaller
    return 0;
  });
}

int ode_dense_jacobian(double t, N_Vector y, N_Vector, SUNMatrix jac, void* user_data, N_Vector,
                       N_Vector, N_Vector) {
  auto* c = static_cast<OdeContext*>(user_data);
  return guarded(c, [&] {
    state_jacobian_blocks(c->model, c->data, t, N_VGetArrayPointer(y), c->blocks);
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
    state_jacobian_blocks(c->model, c->data, t, N_VGetArrayPointer(y), c->blocks);
    const JacobianPattern& p = c->pattern;
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

int ode_normalize(double, N_Vector y, void* user_data) {
  auto* c = static_cast<OdeContext*>(user_data);
  normalize_quaternions(c->model, N_VGetArrayPointer(y));
  return 0;
}

}  // namespace beamrail
