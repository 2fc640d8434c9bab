#include "core/analysis/explicit_stability.hpp"

#include <Spectra/MatOp/SparseCholesky.h>
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsSolver.h>
#include <arkode/arkode_butcher_erk.h>

#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>
#include <vector>

#include "core/model/dynamics.hpp"
#include "core/model/element_kinds.hpp"
#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"

namespace beamrail {
namespace {

// The table's stability function R(z) = 1 + z b^T (I - z A)^-1 1 (A strictly lower triangular).
struct StabilityFunction {
  int stages = 0;
  std::vector<double> a, b;  // a row-major stages x stages
  std::complex<double> operator()(std::complex<double> z) const {
    std::vector<std::complex<double>> k(stages);
    std::complex<double> sum = 0.0;
    for (int i = 0; i < stages; ++i) {
      std::complex<double> s = 1.0;
      for (int j = 0; j < i; ++j) s += z * a[i * stages + j] * k[j];
      k[i] = s;
      sum += b[i] * s;
    }
    return 1.0 + z * sum;
  }
};

// The largest w^2 of K x = w^2 M x at the state posed in `data` (0 when not found).
double largest_eigenvalue(const Model& model, const Data& data) {
  Eigen::SparseMatrix<double> k = -stiffness_matrix(model, data);
  k = 0.5 * Eigen::SparseMatrix<double>(k + Eigen::SparseMatrix<double>(k.transpose()));
  const Eigen::SparseMatrix<double> m = mass_matrix(model, data);
  const Eigen::Index n = k.rows();
  if (n == 0 || k.squaredNorm() == 0.0) return 0.0;  // no elements: no elastic mode
  Spectra::SparseSymMatProd<double> op(k);
  Spectra::SparseCholesky<double> bop(m);
  if (bop.info() != Spectra::CompInfo::Successful) return 0.0;
  Spectra::SymGEigsSolver<Spectra::SparseSymMatProd<double>, Spectra::SparseCholesky<double>,
                          Spectra::GEigsMode::Cholesky>
      eigs(op, bop, 1, std::min<Eigen::Index>(n, 24));
  eigs.init();
  try {
    eigs.compute(Spectra::SortRule::LargestAlge, 1000, 1e-6);
  } catch (const std::exception&) {
    return 0.0;  // Spectra throws where its tridiagonal eigenproblem fails
  }
  if (eigs.info() != Spectra::CompInfo::Successful) return 0.0;
  return std::max(0.0, eigs.eigenvalues()(0));
}

// The largest growth |R(h lambda)|^(duration / h) over the modes up to w_max, lambda the damped
// eigenvalue of a mode of angular frequency w (damping beta w^2).
double growth(const StabilityFunction& r, double w_max, double beta, double h, double duration) {
  constexpr int kSamples = 2000;
  double worst = 0.0;  // of log |R|
  for (int s = 1; s <= kSamples; ++s) {
    const double w = w_max * s / kSamples, zeta = 0.5 * beta * w;
    const std::complex<double> lambda =
        zeta < 1.0 ? std::complex<double>(-zeta * w, w * std::sqrt(1.0 - zeta * zeta))
                   : std::complex<double>(-zeta * w + w * std::sqrt(zeta * zeta - 1.0), 0.0);
    worst = std::max(worst, std::log(std::abs(r(h * lambda))));
  }
  return std::exp(std::min(700.0, worst * std::ceil(duration / h)));
}

}  // namespace

double largest_damping(const Model& model) {
  double beta = 0.0;
  for_each_element(model, [&beta](auto kind, const auto& e, int) {
    beta = std::max(beta, decltype(kind)::damping(e));
  });
  return beta;
}

double fastest_mode(const Model& model, Data& data, const double* y0, double t0) {
  set_state(model, data, y0);
  compute_wrenches(model, data, t0);
  compute_tangent(model, data, t0, false);
  return std::sqrt(largest_eigenvalue(model, data));
}

FixedStepStability fixed_step_stability(const Model& model, Data& data, const double* y0, double t0,
                                        const std::string& arkode_table, double h,
                                        double duration) {
  FixedStepStability out;
  ARKodeButcherTable table = ARKodeButcherTable_LoadERKByName(arkode_table.c_str());
  if (!table) return out;
  StabilityFunction r;
  r.stages = table->stages;
  for (int i = 0; i < r.stages; ++i) {
    r.b.push_back(table->b[i]);
    for (int j = 0; j < r.stages; ++j) r.a.push_back(table->A[i][j]);
  }
  ARKodeButcherTable_Free(table);
  out.fastest = fastest_mode(model, data, y0, t0);
  if (!(out.fastest > 0.0)) return out;
  out.checked = true;
  const double beta = largest_damping(model);
  out.growth = growth(r, out.fastest, beta, h, duration);
  // The longest stable step, from h down by 2 % at a time (the growth need not be monotone in
  // the step: the first one within the limit).
  out.stable_step = h;
  for (int k = 0;
       k < 2000 && growth(r, out.fastest, beta, out.stable_step, duration) > kFixedStepMaxGrowth;
       ++k)
    out.stable_step *= 0.98;
  return out;
}

}  // namespace beamrail
