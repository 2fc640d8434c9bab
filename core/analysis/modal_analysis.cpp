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
// scales(i): the spectrum scale eigenvalue i is compared with to recognise a rigid mode.
void classify(const Eigen::VectorXd& values, const Eigen::MatrixXd& vectors, const SparseMatrix& m,
              const Eigen::VectorXd& scales, int wanted, ModalResult& result) {
  std::vector<int> order(values.size());
  for (int i = 0; i < static_cast<int>(order.size()); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return values(a) < values(b); });
  int elastic = 0;
  for (int i : order) {
    Mode mode;
    mode.eigenvalue = values(i);
    if (std::abs(values(i)) <= kRigidModeThreshold * scales(i)) {
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

// Groups of free bodies coupled by stiffness (the mass matrix is block-diagonal per body): their
// eigenproblems are independent. Each group's degrees of freedom, ascending.
std::vector<std::vector<int>> coupled_groups(const Model& model) {
  const int n = model.n_free();
  std::vector<int> parent(n);
  for (int i = 0; i < n; ++i) parent[i] = i;
  const auto root = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (const auto& b : model.pattern.blocks) parent[root(b.row)] = root(b.col);
  std::vector<std::vector<int>> groups;
  std::vector<int> slot(n, -1);
  for (int i = 0; i < n; ++i) {
    int& g = slot[root(i)];
    if (g < 0) {
      g = static_cast<int>(groups.size());
      groups.emplace_back();
    }
    for (int d = 0; d < kDofsPerBody; ++d) groups[g].push_back(kDofsPerBody * i + d);
  }
  return groups;
}

bool solve_dense(const Model& model, const SparseMatrix& k, const SparseMatrix& m, int wanted,
                 ModalResult& result) {
  const Eigen::MatrixXd kd(k), md(m);
  const Eigen::Index n = kd.rows();
  Eigen::VectorXd values(n), scales(n);
  Eigen::MatrixXd vectors = Eigen::MatrixXd::Zero(n, n);
  Eigen::Index next = 0;
  // Each coupled group on its own: rigid modes are recognised against the group's own spectrum,
  // so a stiff part does not turn the modes of an independent soft part into rigid ones.
  for (const std::vector<int>& dofs : coupled_groups(model)) {
    const Eigen::Index g = static_cast<Eigen::Index>(dofs.size());
    Eigen::MatrixXd kg(g, g), mg(g, g);
    for (Eigen::Index r = 0; r < g; ++r)
      for (Eigen::Index c = 0; c < g; ++c) {
        kg(r, c) = kd(dofs[r], dofs[c]);
        mg(r, c) = md(dofs[r], dofs[c]);
      }
    Eigen::VectorXd gv;
    Eigen::MatrixXd gx;
    if (!solve_dense_eigenproblem(kg, mg, gv, gx)) {
      result.message = "the dense eigensolver failed";
      return false;
    }
    const double scale = gv.cwiseAbs().maxCoeff();
    for (Eigen::Index i = 0; i < g; ++i, ++next) {
      values(next) = gv(i);
      scales(next) = scale;
      for (Eigen::Index r = 0; r < g; ++r) vectors(dofs[r], next) = gx(r, i);
    }
  }
  classify(values, vectors, m, scales, wanted, result);
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
    classify(values, eigs.eigenvectors(), m, Eigen::VectorXd::Constant(values.size(), scale),
             wanted, trial);
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

bool solve_dense_eigenproblem(const Eigen::MatrixXd& kd, const Eigen::MatrixXd& md,
                              Eigen::VectorXd& values, Eigen::MatrixXd& vectors) {
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(kd, md);
  if (eig.info() != Eigen::Success) return false;
  values = eig.eigenvalues();  // ascending
  vectors = eig.eigenvectors();
  const Eigen::Index n = values.size();
  const double top = values.cwiseAbs().maxCoeff();
  if (n < 2 || !(values(0) > kRigidModeThreshold * top) || values(n - 1) < 1e6 * values(0))
    return true;
  const Eigen::LLT<Eigen::MatrixXd> kf(kd);
  const Eigen::LLT<Eigen::MatrixXd> mf(md);
  if (kf.info() != Eigen::Success || mf.info() != Eigen::Success) return true;
  // With M = L L^T: B = L^T K^-1 L has eigenvalues 1/w^2 and eigenvectors y = L^T x.
  const Eigen::MatrixXd l = mf.matrixL();
  Eigen::MatrixXd b = l.transpose() * kf.solve(l);
  b = 0.5 * (b + b.transpose()).eval();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> inv(b);
  if (inv.info() != Eigen::Success || !(inv.eigenvalues().minCoeff() > 0.0)) return true;
  const Eigen::MatrixXd x = mf.matrixU().solve(inv.eigenvectors());
  const double middle = std::sqrt(values(0) * values(n - 1));
  for (Eigen::Index i = 0; i < n && values(i) < middle; ++i) {
    const Eigen::Index j = n - 1 - i;  // 1/w^2 ascending: the i-th smallest w^2 is last but i
    values(i) = 1.0 / inv.eigenvalues()(j);
    vectors.col(i) = x.col(j);
  }
  return true;
}

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
    const SparseMatrix sym = 0.5 * (k + kt);
    const SparseMatrix m = mass_matrix(model, data);
    // Asymmetry of the mass-normalized operator (1/s^2 in every entry): a plain norm of K mixes
    // N/m with N m, so its value would depend on the unit of length.
    const Eigen::VectorXd d = Eigen::VectorXd(m.diagonal()).cwiseSqrt().cwiseInverse();
    const SparseMatrix kn = d.asDiagonal() * k * d.asDiagonal();
    const double norm = kn.norm();
    result.asymmetry = norm > 0.0 ? (kn - SparseMatrix(kn.transpose())).norm() / norm : 0.0;
    const int wanted = std::max(1, options.modes);
    const bool dense =
        options.solver == EigenSolverKind::kDense ||
        (options.solver == EigenSolverKind::kAuto && model.n_dofs <= options.dense_limit) ||
        model.n_dofs < 2 * wanted + 24;
    result.ok = dense ? solve_dense(model, sym, m, wanted, result)
                      : solve_shift_invert(sym, m, wanted, result);
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
