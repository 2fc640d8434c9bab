#include "core/analysis/klu_solver.hpp"

#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

namespace beamrail {
namespace {

constexpr int kS = kStatesPerBody, kP = kPositionStates, kV = kVelocityStates;
using Mat7 = Eigen::Matrix<double, kP, kP>;
using Mat76 = Eigen::Matrix<double, kP, kV>;
using Mat67 = Eigen::Matrix<double, kV, kP>;
using Mat6 = Eigen::Matrix<double, kV, kV>;

struct KluContent {
  std::shared_ptr<const SparseStructure> structure;
  // The last Newton matrix, reduced: per body, the LU of its position block P (7 x 7) and
  // W = P^-1 U (U: position rows, velocity columns); per block, A (velocity rows, position
  // columns); and the values of the velocity-level matrix S = B - A W in the reduced pattern.
  std::vector<Eigen::PartialPivLU<Mat7>> position_lu;
  std::vector<Mat76> w;
  std::vector<Mat67> a;
  std::vector<double> reduced_values;
  std::vector<double> y, r;  // solve work: P^-1 b_p (7 per body), velocity right-hand side
  klu_l_numeric* numeric = nullptr;
  klu_l_common common;
  sunindextype last_flag = 0;
  double fresh_growth = 1.0;  // reciprocal pivot growth of the last factorization with pivoting

  void drop_numeric() {
    if (numeric) klu_l_free_numeric(&numeric, &common);
  }
};

KluContent& content(SUNLinearSolver s) { return *static_cast<KluContent*>(s->content); }

SUNLinearSolver_Type type(SUNLinearSolver) { return SUNLINEARSOLVER_DIRECT; }
SUNLinearSolver_ID id(SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; }

int initialize(SUNLinearSolver s) {
  content(s).drop_numeric();  // the next setup factors afresh, choosing new pivots
  content(s).last_flag = SUNLS_SUCCESS;
  return SUNLS_SUCCESS;
}

// Factors A (the structure's pattern with new values): the first time, and whenever the pivots of
// the last factorization went bad for the new values, with partial pivoting; otherwise by reusing
// those pivots (a refactorization, several times cheaper).
int setup(SUNLinearSolver s, SUNMatrix m) {
  KluContent& c = content(s);
  const SparseStructure& st = *c.structure;
  if (SUNSparseMatrix_Columns(m) != st.n() ||
      SUNSparseMatrix_IndexPointers(m)[st.n()] != st.pattern().nnz()) {
    c.last_flag = SUNLS_ILL_INPUT;
    return SUNLS_ILL_INPUT;
  }
  // Reduce M = I - gamma J to the velocity level. Position rows couple a body to itself only
  // (dc/dt = v, dq/dt = q (x) w / 2), so each body's position block P inverts on its own; it is
  // I - gamma dq'/dq, never singular.
  const double* values = SUNSparseMatrix_Data(m);
  const long* pos = st.pattern().positions.data();
  const auto entry = [&](size_t b, int r, int col) {
    const long k = pos[b * kS * kS + kS * r + col];
    return k >= 0 ? values[k] : 0.0;
  };
  const auto& blocks = st.blocks();
  const size_t bodies = static_cast<size_t>(st.n() / kS);
  c.position_lu.resize(bodies);
  c.w.resize(bodies);
  c.a.resize(blocks.size());
  c.reduced_values.resize(static_cast<size_t>(st.reduced().nnz()));
  for (size_t j = 0; j < bodies; ++j) {  // block j is body j's diagonal block
    Mat7 p;
    Mat76 u;
    for (int r = 0; r < kP; ++r) {
      for (int col = 0; col < kP; ++col) p(r, col) = entry(j, r, col);
      for (int col = 0; col < kV; ++col) u(r, col) = entry(j, r, kP + col);
    }
    c.position_lu[j].compute(p);
    c.w[j] = c.position_lu[j].solve(u);
    if (!c.w[j].allFinite()) {
      c.last_flag = SUNLS_PACKAGE_FAIL_REC;
      return SUNLS_PACKAGE_FAIL_REC;
    }
  }
  const long* reduced_pos = st.reduced().positions.data();
  for (size_t b = 0; b < blocks.size(); ++b) {
    Mat67& a = c.a[b];
    Mat6 bv;
    for (int r = 0; r < kV; ++r) {
      for (int col = 0; col < kP; ++col) a(r, col) = entry(b, kP + r, col);
      for (int col = 0; col < kV; ++col) bv(r, col) = entry(b, kP + r, kP + col);
    }
    const Mat6 schur = bv - a * c.w[static_cast<size_t>(blocks[b].col)];
    for (int r = 0; r < kV; ++r)
      for (int col = 0; col < kV; ++col)
        c.reduced_values[static_cast<size_t>(reduced_pos[b * kV * kV + kV * r + col])] =
            schur(r, col);
  }

  klu_l_symbolic* symbolic = st.symbolic();
  long* starts = const_cast<long*>(st.reduced().column_starts.data());  // KLU reads only
  long* rows = const_cast<long*>(st.reduced().rows.data());
  double* reduced = c.reduced_values.data();
  if (c.numeric) {
    // The old pivots are kept while the pivot growth stays within a factor 1e3 of what partial
    // pivoting achieved on the values it chose them for: beyond it the factors lose digits (a test
    // shows 4e-4 relative residuals with the old pivots where new ones give 1e-16). SUNDIALS' own
    // KLU solver tests the condition estimates instead; on a 10,000-body chain the reciprocal
    // estimate min|u_ii| / max|u_ii| sat near 3e-11 for every Newton matrix, so that test paid a
    // condition estimate and a fresh factorization at 6 of 7 setups, gaining no accuracy.
    const bool kept = klu_l_refactor(starts, rows, reduced, symbolic, c.numeric, &c.common) &&
                      c.common.status == KLU_OK &&
                      klu_l_rgrowth(starts, rows, reduced, symbolic, c.numeric, &c.common) &&
                      c.common.rgrowth >= 1e-3 * c.fresh_growth;
    if (kept) {
      c.last_flag = SUNLS_SUCCESS;
      return SUNLS_SUCCESS;
    }
    c.drop_numeric();
  }
  c.numeric = klu_l_factor(starts, rows, reduced, symbolic, &c.common);
  // A singular Newton matrix is recoverable: the integrator retries with a smaller step.
  if (!c.numeric) {
    c.last_flag = SUNLS_PACKAGE_FAIL_REC;
    return SUNLS_PACKAGE_FAIL_REC;
  }
  c.fresh_growth =
      klu_l_rgrowth(starts, rows, reduced, symbolic, c.numeric, &c.common) ? c.common.rgrowth : 1.0;
  c.last_flag = SUNLS_SUCCESS;
  return SUNLS_SUCCESS;
}

// x_p = P^-1 (b_p - U x_v) per body, where S x_v = b_v - A P^-1 b_p.
int solve(SUNLinearSolver s, SUNMatrix, N_Vector x, N_Vector b, double) {
  KluContent& c = content(s);
  const SparseStructure& st = *c.structure;
  if (!c.numeric) {
    c.last_flag = SUNLS_PACKAGE_FAIL_REC;
    return SUNLS_PACKAGE_FAIL_REC;
  }
  const size_t bodies = c.position_lu.size();
  const double* bd = N_VGetArrayPointer(b);
  c.y.resize(bodies * kP);
  c.r.resize(bodies * kV);
  for (size_t j = 0; j < bodies; ++j) {
    Eigen::Map<Eigen::Matrix<double, kP, 1>>(c.y.data() + kP * j) =
        c.position_lu[j].solve(Eigen::Map<const Eigen::Matrix<double, kP, 1>>(bd + kS * j));
    Eigen::Map<Eigen::Matrix<double, kV, 1>>(c.r.data() + kV * j) =
        Eigen::Map<const Eigen::Matrix<double, kV, 1>>(bd + kS * j + kP);
  }
  const auto& blocks = st.blocks();
  for (size_t k = 0; k < blocks.size(); ++k)
    Eigen::Map<Eigen::Matrix<double, kV, 1>>(c.r.data() + kV * blocks[k].row) -=
        c.a[k] * Eigen::Map<const Eigen::Matrix<double, kP, 1>>(c.y.data() + kP * blocks[k].col);
  if (!klu_l_solve(st.symbolic(), c.numeric, st.n_reduced(), 1, c.r.data(), &c.common)) {
    c.last_flag = SUNLS_PACKAGE_FAIL_REC;
    return SUNLS_PACKAGE_FAIL_REC;
  }
  double* xd = N_VGetArrayPointer(x);
  for (size_t j = 0; j < bodies; ++j) {
    const Eigen::Map<const Eigen::Matrix<double, kV, 1>> xv(c.r.data() + kV * j);
    Eigen::Map<Eigen::Matrix<double, kV, 1>>(xd + kS * j + kP) = xv;
    Eigen::Map<Eigen::Matrix<double, kP, 1>>(xd + kS * j) =
        Eigen::Map<const Eigen::Matrix<double, kP, 1>>(c.y.data() + kP * j) - c.w[j] * xv;
  }
  c.last_flag = SUNLS_SUCCESS;
  return SUNLS_SUCCESS;
}

sunindextype last_flag(SUNLinearSolver s) { return content(s).last_flag; }

int free_solver(SUNLinearSolver s) {
  if (!s) return SUNLS_SUCCESS;
  if (s->content) {
    content(s).drop_numeric();
    delete static_cast<KluContent*>(s->content);
    s->content = nullptr;
  }
  SUNLinSolFreeEmpty(s);
  return SUNLS_SUCCESS;
}

}  // namespace

SUNLinearSolver make_klu_solver(std::shared_ptr<const SparseStructure> structure, SUNContext ctx) {
  SUNLinearSolver s = SUNLinSolNewEmpty(ctx);
  if (!s) return nullptr;
  auto* c = new KluContent;
  c->structure = std::move(structure);
  klu_l_defaults(&c->common);
  s->content = c;
  s->ops->gettype = type;
  s->ops->getid = id;
  s->ops->initialize = initialize;
  s->ops->setup = setup;
  s->ops->solve = solve;
  s->ops->lastflag = last_flag;
  s->ops->free = free_solver;
  return s;
}

}  // namespace beamrail
