#include "core/analysis/modal_analysis.hpp"

#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/MatOp/SymShiftInvert.h>
#include <Spectra/SymGEigsShiftSolver.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"

namespace beamrail {
namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;

// Classifies eigenpairs, normalizes shapes, and keeps the rigid modes plus `wanted` others.
void classify(const Eigen::VectorXd& values, const Eigen::MatrixXd& vectors, const SparseMatrix& m,
              double scale, int wanted, ModalResult& result) {
  std::vector<int> order(values.size());
  for (int i = 0; i < static_cast<int>(order.size()); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return values(a) < values(b); });
  int elastic = 0;
  for (int i : order) {
    Mode mode;
    mode.eigenvalue = values(i);
    if (std::abs(values(i)) <= kRigidModeThreshold * scale) {
      mode.kind = Mode::Kind::kRigid;
      ++result.rigid_modes;
    } else if (values(i) < 0.0) {
      mode.kind = Mode::Kind::kUnstable;
      mode.frequency_hz = -std::sqrt(-values(i)) / (2 * std::numbers::pi);
    } else {
      if (elastic == wanted) continue;
      ++elastic;
      mode.frequency_hz = std::sqrt(values(i)) / (2 * std::numbers::pi);
    }
    Eigen::VectorXd x = vectors.col(i);
    x /= std::sqrt(x.dot(m * x));
    Eigen::Index big = 0;
    x.cwiseAbs().maxCoeff(&big);
    if (x(big) < 0) x = -x;
    mode.shape = x;
    result.modes.push_back(std::move(mode));
  }
  for (const Mode& mode : result.modes)
    if (mode.kind == Mode::Kind::kUnstable)
      result.warnings.push_back(
          "the configuration is unstable (a mode has negative stiffness: "
          "buckling or an unstable equilibrium)");
}

bool solve_dense(const SparseMatrix& k, const SparseMatrix& m, int wanted, ModalResult& result) {
  const Eigen::MatrixXd kd(k), md(m);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(kd, md);
  if (eig.info() != Eigen::Success) {
    result.message = "the dense eigensolver failed";
    return false;
  }
  const double scale = eig.eigenvalues().cwiseAbs().maxCoeff();
  classify(eig.eigenvalues(), eig.eigenvectors(), m, scale, wanted, result);
  result.solver = "dense";
  return true;
}

bool solve_shift_invert(const SparseMatrix& k, const SparseMatrix& m, int wanted,
                        ModalResult& result) {
  const Eigen::Index n = k.rows();
  // Scale of the spectrum from the diagonal, to place a small negative shift below the rigid
  // modes (K is singular when the scene floats or holds a mechanism).
  double scale = 0.0;
  for (Eigen::Index i = 0; i < n; ++i)
    scale = std::max(scale, k.coeff(i, i) / std::max(m.coeff(i, i), 1e-300));
  const double sigma = -1e-6 * scale;
  for (int extra : {12, 48, 192}) {
    const Eigen::Index nev = std::min<Eigen::Index>(n - 2, wanted + extra);
    const Eigen::Index ncv = std::min<Eigen::Index>(n, std::max<Eigen::Index>(2 * nev + 1, 20));
    using Op = Spectra::SymShiftInvert<double, Eigen::Sparse, Eigen::Sparse>;
    using BOp = Spectra::SparseSymMatProd<double>;
    Op op(k, m);
    BOp bop(m);
    Spectra::SymGEigsShiftSolver<Op, BOp, Spectra::GEigsMode::ShiftInvert> eigs(op, bop, nev, ncv,
                                                                                sigma);
    eigs.init();
    eigs.compute(Spectra::SortRule::LargestMagn, 1000, 1e-12);
    if (eigs.info() != Spectra::CompInfo::Successful) {
      result.message = "the shift-invert eigensolver did not converge";
      return false;
    }
    const Eigen::VectorXd values = eigs.eigenvalues();
    ModalResult trial;
    classify(values, eigs.eigenvectors(), m, scale, wanted, trial);
    const int elastic = static_cast<int>(trial.modes.size()) - trial.rigid_modes;
    if (elastic >= wanted || nev >= n - 2) {
      result.modes = std::move(trial.modes);
      result.rigid_modes = trial.rigid_modes;
      result.warnings.insert(result.warnings.end(), trial.warnings.begin(), trial.warnings.end());
      result.solver = "shift-invert";
      return true;
    }
  }
  result.message = "could not find the requested number of elastic modes";
  return false;
}

}  // namespace

const Mode* elastic_mode(const ModalResult& result, int k) {
  int count = 0;
  for (const Mode& mode : result.modes)
    if (mode.kind != Mode::Kind::kRigid && ++count == k) return &mode;
  return nullptr;
}

ModalResult solve_modal(const Model& model, const ModalOptions& options, Data& data) {
  const auto start = std::chrono::steady_clock::now();
  ModalResult result;
  try {
    compute_wrenches(model, data, options.time, options.load_factor);
    compute_tangent(model, data, options.time, false, options.load_factor);
    const SparseMatrix s = stiffness_matrix(model, data);
    const SparseMatrix k = -s;
    const SparseMatrix kt = SparseMatrix(k.transpose());
    const double norm = k.norm();
    result.asymmetry = norm > 0.0 ? (k - kt).norm() / norm : 0.0;
    const SparseMatrix sym = 0.5 * (k + kt);
    const SparseMatrix m = mass_matrix(model, data);
    const int wanted = std::max(1, options.modes);
    const bool dense =
        options.solver == EigenSolverKind::kDense ||
        (options.solver == EigenSolverKind::kAuto && model.n_dofs <= options.dense_limit) ||
        model.n_dofs < 2 * wanted + 24;
    result.ok =
        dense ? solve_dense(sym, m, wanted, result) : solve_shift_invert(sym, m, wanted, result);
    if (result.ok && result.asymmetry > 1e-6)
      result.warnings.push_back("the tangent stiffness is not symmetric (relative asymmetry " +
                                std::to_string(result.asymmetry) +
                                "): the configuration is not an equilibrium; its symmetric part "
                                "was used");
  } catch (const std::exception& e) {
    result.ok = false;
    result.message = e.what();
  }
  result.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace beamrail
