#include "core/analysis/modal_analysis.hpp"

#include <Spectra/GenEigsRealShiftSolver.h>
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <memory>
#include <numbers>
#include <stdexcept>

#include "core/analysis/axial_force_check.hpp"
#include "core/analysis/deadline.hpp"
#include "core/analysis/dense_eigen.hpp"
#include "core/analysis/element_deformation.hpp"
#include "core/analysis/sparse_structure.hpp"
#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"

namespace beamrail {
namespace {

// kModalNoiseError where joints hold bodies: their penalty stiffness dwarfs the structure's, and
// the soft modes' eigenvalues round by a larger share of their noise: 0.065 of it on
// studies/hinged_bob.json's swing (noise 1.8e-3; 1.15e-4 below the same scene at
// relative_compliance 1e-4), 0.018 and 2.6e-3 on a column held by revolute joints of
// relative_compliance 1e-10 and 1e-8 (an adversarial review, 2026-12-01, found the figure 1e-3
// times the noise 18 to 60 times short there).
constexpr double kModalNoiseErrorJoints = 0.1;

using SparseMatrix = Eigen::SparseMatrix<double>;
using Clock = std::chrono::steady_clock;

// The shift mu of the inverse problem. 0 when the elastic stiffness is positive definite: the
// inverse problem then resolves the lowest eigenvalue to its own relative accuracy however stiff
// the rest is. Otherwise a small multiple of the stiffness scale, far enough above rounding
// (eps times the largest K_ii / M_ii) that K + mu M stays definite along rigid directions.
double choose_shift(const Model& model, const SparseMatrix& k, const SparseMatrix& m) {
  if (held_by_beams(model)) return 0.0;
  double scale = 0.0;
  for (Eigen::Index i = 0; i < k.rows(); ++i)
    scale = std::max(scale, std::abs(k.coeff(i, i)) / m.coeff(i, i));
  return scale > 0.0 ? 1e4 * std::numeric_limits<double>::epsilon() * scale : 1.0;
}

// Eigen's SimplicialLDLT factoring a matrix already permuted, P A P^T (upper triangle), as it
// factors A internally after choosing P: the same symbolic and numeric steps in the same order, so
// the same factors to the last bit, without the copies compute() makes of a preordered matrix.
class PreorderedLdlt
    : public Eigen::SimplicialLDLT<SparseMatrix, Eigen::Upper, Eigen::NaturalOrdering<int>> {
 public:
  void compute_preordered(const SparseMatrix& upper) {
    m_P.resize(0);
    m_Pinv.resize(0);
    analyzePattern_preordered(upper, true);
    factorize_preordered<true>(upper);
  }
};

// y = (K - sigma M)^-1 x for Spectra's shift-invert mode, by a sparse LDL^T (K - sigma M is
// definite, or mildly indefinite about an unstable configuration) of P (K - sigma M) P^T with the
// fill-reducing ordering P: the topology's, shared between the designs of a sweep when a cache
// is given (ModalOptions::structure_cache), else its own. Either way the steps of
// SimplicialLDLT<SparseMatrix> on K - sigma M, which chooses the same P: the same factors and
// solutions to the last bit, with or without the cache.
class ShiftSolve {
 public:
  using Scalar = double;
  ShiftSolve(const SparseMatrix& k, const SparseMatrix& m, const SymmetricOrdering* ordering,
             const Deadline& budget)
      : k_(k), m_(m), ordering_(ordering), budget_(budget) {}
  Eigen::Index rows() const { return k_.rows(); }
  Eigen::Index cols() const { return k_.cols(); }
  void set_shift(double sigma) {
    budget_.check();
    // K - sigma M: K's pattern holds M's (a body's own block), so the shift changes K's entries
    // in place of a sparse sum, each to k - sigma m as the sum computes it; no copy when sigma = 0.
    const SparseMatrix* a = &k_;
    SparseMatrix shifted;
    if (sigma != 0.0) {
      shifted = k_;
      for (Eigen::Index c = 0; c < m_.outerSize(); ++c)
        for (SparseMatrix::InnerIterator it(m_, c); it; ++it)
          shifted.coeffRef(it.row(), c) -= sigma * it.value();
      a = &shifted;
    }
    if (!ordering_) {
      own_ordering_ = symmetric_ordering(*a);
      ordering_ = &own_ordering_;
    }
    inverse_ = ordering_->inverse();
    SparseMatrix upper(a->rows(), a->cols());
    upper.selfadjointView<Eigen::Upper>() =
        a->selfadjointView<Eigen::Lower>().twistedBy(*ordering_);
    budget_.check();
    ldlt_.compute_preordered(upper);
    if (ldlt_.info() != Eigen::Success)
      throw std::runtime_error("the shifted stiffness K + mu M could not be factored");
    budget_.check();
  }
  void perform_op(const double* x, double* y) const {
    budget_.check();
    work_.noalias() = *ordering_ * Eigen::Map<const Eigen::VectorXd>(x, rows());
    ldlt_.matrixL().solveInPlace(work_);
    work_ = ldlt_.vectorD().asDiagonal().inverse() * work_;
    ldlt_.matrixU().solveInPlace(work_);
    Eigen::Map<Eigen::VectorXd>(y, rows()).noalias() = inverse_ * work_;
  }

 private:
  const SparseMatrix& k_;
  const SparseMatrix& m_;
  const SymmetricOrdering* ordering_;
  const Deadline& budget_;
  SymmetricOrdering own_ordering_, inverse_;
  PreorderedLdlt ldlt_;
  mutable Eigen::VectorXd work_;  // the permuted right-hand side, solved in place
};

struct Eigenpairs {
  Eigen::VectorXd values;
  Eigen::MatrixXd vectors;  // columns
};

bool solve_dense(const SparseMatrix& k, const SparseMatrix& m, double shift, Eigenpairs& out) {
  return solve_dense_eigenproblem(Eigen::MatrixXd(k), Eigen::MatrixXd(m), out.values, out.vectors,
                                  shift);
}

// The `count` eigenpairs nearest the shift -mu by Lanczos; false when it did not converge.
bool solve_lanczos(const SparseMatrix& k, const SparseMatrix& m, double shift, Eigen::Index count,
                   const SymmetricOrdering* ordering, const Deadline& budget, Eigenpairs& out) {
  const Eigen::Index n = k.rows();
  const Eigen::Index nev = std::min<Eigen::Index>(n - 1, count);
  const Eigen::Index ncv = std::min<Eigen::Index>(n, std::max<Eigen::Index>(2 * nev + 1, 20));
  ShiftSolve op(k, m, ordering, budget);
  Spectra::SparseSymMatProd<double> bop(m);
  Spectra::SymGEigsShiftSolver<ShiftSolve, Spectra::SparseSymMatProd<double>,
                               Spectra::GEigsMode::ShiftInvert>
      eigs(op, bop, nev, ncv, -shift);
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestMagn, 1000, 1e-12);
  if (eigs.info() != Spectra::CompInfo::Successful) return false;
  out.values = eigs.eigenvalues();
  out.vectors = eigs.eigenvectors();
  return true;
}

// Whether loads without a potential (torques of fixed direction, follower loads) load the state
// linearized.
bool loaded_nonconservatively(const Model& model, const ModalOptions& options) {
  if (options.load_factor == 0.0) return false;
  for (const Load& load : model.loads)
    if (!is_conservative(load) && load.value != Vec3::Zero()) return true;
  return false;
}

// y = L^T (K - sigma M)^-1 L x = (A - sigma I)^-1 x for A = L^-1 K L^-T, M = L L^T: the
// shift-invert operator of the non-symmetric problem for Spectra's Arnoldi, by a sparse LU.
class NonsymmetricShiftSolve {
 public:
  using Scalar = double;
  NonsymmetricShiftSolve(const SparseMatrix& k, const SparseMatrix& m, const SparseMatrix& l,
                         const Deadline& budget)
      : k_(k), m_(m), l_(l), budget_(budget) {}
  Eigen::Index rows() const { return k_.rows(); }
  Eigen::Index cols() const { return k_.cols(); }
  void set_shift(double sigma) {
    budget_.check();
    SparseMatrix a = k_ - sigma * m_;
    a.makeCompressed();
    lu_.compute(a);
    if (lu_.info() != Eigen::Success)
      throw std::runtime_error("the shifted stiffness K + mu M could not be factored");
    budget_.check();
  }
  void perform_op(const double* x, double* y) const {
    budget_.check();
    const Eigen::VectorXd lx = l_ * Eigen::Map<const Eigen::VectorXd>(x, rows());
    Eigen::Map<Eigen::VectorXd>(y, rows()) = l_.transpose() * lu_.solve(lx);
  }

 private:
  const SparseMatrix& k_;
  const SparseMatrix& m_;
  const SparseMatrix& l_;
  const Deadline& budget_;
  Eigen::SparseLU<SparseMatrix> lu_;
};

// The `count` eigenvalues of the non-symmetric K x = lambda M x nearest -shift by Arnoldi with
// shift-invert (Spectra), M = L L^T; eigenvectors L^T x when `vectors` is given.
bool arnoldi_nonsymmetric(const SparseMatrix& k, const SparseMatrix& m, const SparseMatrix& l,
                          double shift, Eigen::Index count, const Deadline& budget,
                          Eigen::VectorXcd& values, Eigen::MatrixXcd* vectors) {
  const Eigen::Index n = k.rows();
  const Eigen::Index nev = std::min<Eigen::Index>(n - 2, count);
  const Eigen::Index ncv = std::min<Eigen::Index>(n, std::max<Eigen::Index>(2 * nev + 1, 20));
  NonsymmetricShiftSolve op(k, m, l, budget);
  Spectra::GenEigsRealShiftSolver<NonsymmetricShiftSolve> eigs(op, nev, ncv, -shift);
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestMagn, 1000, 1e-12);
  if (eigs.info() != Spectra::CompInfo::Successful) return false;
  values = eigs.eigenvalues();
  if (vectors) *vectors = eigs.eigenvectors();
  return true;
}

// The eigenpairs of the non-symmetric K x = w^2 M x (K = -S at a state under torques of fixed
// direction, which do no conservative work): with M = L L^T, A = L^-1 K L^-T has the same
// eigenvalues and the eigenvectors L^T x. All pairs densely, or the `count` nearest -shift by
// Arnoldi with shift-invert. Real pairs go to `out`; complex ones (flutter: a vibration that
// grows) are counted in *complex_pairs (one per conjugate pair) with the largest
// |Im w^2| / |w^2| in *growth. False when the eigensolver did not converge.
bool solve_nonsymmetric(const SparseMatrix& k, const SparseMatrix& m, double shift,
                        Eigen::Index count, bool dense, const Deadline& budget, Eigenpairs& out,
                        int* complex_pairs, double* growth) {
  const Eigen::Index n = k.rows();
  const Eigen::SimplicialLLT<SparseMatrix, Eigen::Lower, Eigen::NaturalOrdering<int>> mf(m);
  if (mf.info() != Eigen::Success)
    throw std::runtime_error("the mass matrix is not positive definite");
  const SparseMatrix l = mf.matrixL();
  Eigen::VectorXcd values;
  Eigen::MatrixXcd vectors;
  if (dense || n < count + 3) {
    if (!solve_dense_nonsymmetric(Eigen::MatrixXd(k), Eigen::MatrixXd(m), values, &vectors))
      return false;
  } else if (!arnoldi_nonsymmetric(k, m, l, shift, count, budget, values, &vectors)) {
    return false;
  }
  // A real eigenvalue of a real matrix may carry a rounding-level imaginary part; 1e-6 of its
  // size (a growth of the amplitude by 3e-6 rad per radian of vibration) tells them apart.
  std::vector<Eigen::Index> real;
  *complex_pairs = 0;
  *growth = 0.0;
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    const double size = std::max(std::abs(values(i)), shift);
    if (std::abs(values(i).imag()) <= 1e-6 * size) {
      real.push_back(i);
    } else if (values(i).imag() > 0.0) {
      ++*complex_pairs;
      *growth = std::max(*growth, std::abs(values(i).imag()) / std::abs(values(i)));
    }
  }
  out.values.resize(static_cast<Eigen::Index>(real.size()));
  out.vectors.resize(n, static_cast<Eigen::Index>(real.size()));
  for (size_t j = 0; j < real.size(); ++j) {
    Eigen::VectorXcd psi = vectors.col(real[j]);
    Eigen::Index big = 0;
    psi.cwiseAbs().maxCoeff(&big);
    psi *= std::conj(psi(big)) / std::abs(psi(big));  // the phase that makes it real
    out.values(static_cast<Eigen::Index>(j)) = values(real[j]).real();
    out.vectors.col(static_cast<Eigen::Index>(j)) = mf.matrixU().solve(Eigen::VectorXd(psi.real()));
  }
  return true;
}

// Builds the modes (ascending), classifying each by the element deformation of its shape; keeps
// every rigid mode and at most `wanted` others. Returns the number of non-rigid modes among
// the pairs (kept or not).
int classify(const Eigenpairs& pairs, const SparseMatrix& m, const ElementDeformation& deformation,
             double shift, int wanted, ModalResult& result) {
  std::vector<Eigen::Index> order(pairs.values.size());
  for (Eigen::Index i = 0; i < pairs.values.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](Eigen::Index a, Eigen::Index b) { return pairs.values(a) < pairs.values(b); });
  // A rigid mode's eigenvalue is load stiffness only; below this it is rounding of the shift.
  const double resolution = 1e-6 * shift;
  int others = 0;
  result.modes.clear();
  result.rigid_modes = 0;
  for (Eigen::Index i : order) {
    Mode mode;
    mode.eigenvalue = pairs.values(i);
    Eigen::VectorXd x = pairs.vectors.col(i);
    x /= std::sqrt(x.dot(m * x));
    mode.deformation = deformation.ratio(x);
    if (mode.deformation <= kRigidModeDeformation) {
      mode.kind = Mode::Kind::kRigid;
      ++result.rigid_modes;
      if (std::abs(mode.eigenvalue) <= resolution) mode.eigenvalue = 0.0;
    } else {
      if (others++ >= wanted) continue;
      mode.kind = mode.eigenvalue < 0.0 ? Mode::Kind::kUnstable : Mode::Kind::kElastic;
    }
    mode.frequency_hz = std::copysign(std::sqrt(std::abs(mode.eigenvalue)), mode.eigenvalue) /
                        (2 * std::numbers::pi);
    Eigen::Index big = 0;
    x.cwiseAbs().maxCoeff(&big);
    if (x(big) < 0) x = -x;
    mode.shape = std::move(x);
    result.modes.push_back(std::move(mode));
  }
  return others;
}

// The rigid motions r_d (columns: translations along the global axes, rotations about the global
// axes through the free bodies' centre of mass), the modes' participations x^T M r_d and the
// totals r_d^T M r_d.
void participations(const Model& model, const Data& data, const SparseMatrix& m,
                    ModalResult& result) {
  double total = 0.0;
  Vec3 weighted = Vec3::Zero();
  for (int k = 0; k < model.n_free(); ++k) {
    const double mass = model.bodies[model.free_bodies[k]].mass;
    total += mass;
    weighted += mass * centre(model, data, model.free_bodies[k]);
  }
  result.reference_point = total > 0.0 ? Vec3(weighted / total) : Vec3::Zero();
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(model.n_dofs, 6);
  for (int k = 0; k < model.n_free(); ++k) {
    const Vec3 c = centre(model, data, model.free_bodies[k]) - result.reference_point;
    for (int d = 0; d < 3; ++d) {
      r(kDofsPerBody * k + d, d) = 1.0;
      r.block<3, 1>(kDofsPerBody * k, 3 + d) = Vec3::Unit(d).cross(c);
      r(kDofsPerBody * k + 3 + d, 3 + d) = 1.0;
    }
  }
  const Eigen::MatrixXd mr = m * r;
  result.rigid_mass = (r.transpose() * mr).diagonal();
  for (Mode& mode : result.modes) mode.participation = (mode.shape.transpose() * mr).transpose();
}

// The inverse problem M x = nu (K + mu M) x, a = K + mu M: nu = 1/(w^2 + mu) and M-normalized
// x. False when it could not be solved.
bool solve_inverse_problem(const Eigen::MatrixXd& a, const Eigen::MatrixXd& md, Eigen::VectorXd& nu,
                           Eigen::MatrixXd& x) {
  // a positive definite, where the automatic choice is LAPACK (lapack_eigen_automatic): the
  // pencil (M, a) as it stands, its vectors a-normalized (x^T a x = 1, so x^T M x = nu): one
  // call instead of the two factorizations, the solves and the eigensolver below.
  if (lapack_eigen_automatic(a.rows()) &&
      generalized_symmetric_eigen(md, a, nu, x, DenseEigenDriver::kLapack) &&
      (nu.array() > 0.0).all()) {
    for (Eigen::Index j = 0; j < nu.size(); ++j) x.col(j) /= std::sqrt(nu(j));
    return true;
  }
  const Eigen::LLT<Eigen::MatrixXd> mf(md);
  if (mf.info() != Eigen::Success) return false;
  // With M = L L^T: B = L^T a^-1 L has eigenvalues 1/(w^2 + mu), eigenvectors L^T x. Cholesky
  // where a is positive definite (the usual case), else a pivoted LDL^T.
  const Eigen::MatrixXd l = mf.matrixL();
  Eigen::MatrixXd b;
  if (const Eigen::LLT<Eigen::MatrixXd> llt(a); llt.info() == Eigen::Success) {
    b = l.transpose() * llt.solve(l);
  } else {
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(a);
    if (ldlt.info() != Eigen::Success) return false;
    b = l.transpose() * ldlt.solve(l);
  }
  if (!b.allFinite()) return false;
  b = 0.5 * (b + b.transpose()).eval();
  Eigen::MatrixXd y;
  if (!symmetric_eigen(b, nu, y)) return false;
  x = mf.matrixU().solve(y);
  return true;
}

}  // namespace

bool solve_dense_eigenproblem(const Eigen::MatrixXd& kd, const Eigen::MatrixXd& md,
                              Eigen::VectorXd& values, Eigen::MatrixXd& vectors, double shift) {
  if (!generalized_symmetric_eigen(kd, md, values, vectors)) return false;  // ascending
  const Eigen::Index n = values.size();
  if (n < 2) return true;
  double mu = shift;
  if (mu < 0.0) {
    // No shift given: the inverse problem only for a positive definite K of a wide spectrum.
    const double top = values.cwiseAbs().maxCoeff();
    if (!(values(0) > 1e-12 * top) || values(n - 1) < 1e6 * values(0)) return true;
    mu = 0.0;
  }
  Eigen::VectorXd nu;
  Eigen::MatrixXd x;
  if (!solve_inverse_problem(kd + mu * md, md, nu, x)) return true;
  // nu = 1/(w^2 + mu): the largest |nu| are the eigenvalues nearest -mu. Order them by w^2.
  std::vector<Eigen::Index> order(n);
  for (Eigen::Index i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](Eigen::Index a, Eigen::Index c) { return 1.0 / nu(a) < 1.0 / nu(c); });
  // The inverse problem resolves w^2 to ~eps (w^2 + mu) / min |w^2 + mu|, the direct one to
  // ~eps lambda_max / w^2: the inverse below their geometric mean, the direct above.
  const double top = values.cwiseAbs().maxCoeff();
  const double bottom = 1.0 / nu.cwiseAbs().maxCoeff();
  const double middle = std::sqrt(top * bottom);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double lambda = 1.0 / nu(order[i]) - mu;
    if (!(std::abs(lambda + mu) < middle) || !std::isfinite(lambda)) break;
    values(i) = lambda;
    vectors.col(i) = x.col(order[i]);
  }
  return true;
}

bool solve_dense_nonsymmetric(const Eigen::MatrixXd& k, const Eigen::MatrixXd& m,
                              Eigen::VectorXcd& values, Eigen::MatrixXcd* vectors) {
  const Eigen::LLT<Eigen::MatrixXd> mf(m);
  if (mf.info() != Eigen::Success) return false;
  const Eigen::MatrixXd l = mf.matrixL();
  Eigen::MatrixXd a = l.triangularView<Eigen::Lower>().solve(k);
  a = l.triangularView<Eigen::Lower>().solve(Eigen::MatrixXd(a.transpose())).transpose();
  const Eigen::EigenSolver<Eigen::MatrixXd> eig(a, vectors != nullptr);
  if (eig.info() != Eigen::Success) return false;
  values = eig.eigenvalues();
  if (vectors) *vectors = eig.eigenvectors();
  return true;
}

bool nonsymmetric_eigenvalues_near(const Eigen::SparseMatrix<double>& k,
                                   const Eigen::SparseMatrix<double>& m, double shift,
                                   Eigen::Index count, Eigen::VectorXcd& values) {
  const Eigen::SimplicialLLT<SparseMatrix, Eigen::Lower, Eigen::NaturalOrdering<int>> mf(m);
  if (mf.info() != Eigen::Success) return false;
  const SparseMatrix l = mf.matrixL();
  try {
    return arnoldi_nonsymmetric(k, m, l, shift, count, Deadline{}, values, nullptr);
  } catch (const std::exception&) {
    return false;
  }
}

Vec6 effective_mass_fraction(const Mode& mode, const ModalResult& result) {
  Vec6 f = Vec6::Zero();
  for (int d = 0; d < 6; ++d)
    if (result.rigid_mass(d) > 0.0)
      f(d) = mode.participation(d) * mode.participation(d) / result.rigid_mass(d);
  return f;
}

int dominant_direction(const Mode& mode, const ModalResult& result) {
  const Vec6 f = effective_mass_fraction(mode, result);
  int best = -1;
  for (int d = 0; d < 6; ++d)
    if (f(d) > 1e-12 && (best < 0 || f(d) > f(best))) best = d;
  return best;
}

double modal_assurance(const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                       const Eigen::SparseMatrix<double>& m) {
  const double ab = a.dot(m * b), aa = a.dot(m * a), bb = b.dot(m * b);
  return aa > 0.0 && bb > 0.0 ? ab * ab / (aa * bb) : 0.0;
}

const Mode* elastic_mode(const ModalResult& result, int k) {
  int count = 0;
  for (const Mode& mode : result.modes)
    if (mode.kind != Mode::Kind::kRigid && ++count == k) return &mode;
  return nullptr;
}

namespace {

bool refuse_options(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

std::string hz_text(double hz) {
  char text[48];
  std::snprintf(text, sizeof text, "%.4g Hz", hz);
  return text;
}

}  // namespace

bool ModalOptions::IsValid(std::string* error) const {
  if (modes < 1) return refuse_options(error, "modes must be at least 1");
  if (guard_modes < 0) return refuse_options(error, "guard_modes must be at least 0");
  if (std::isnan(time)) return refuse_options(error, "time must be a number");
  if (!std::isfinite(load_factor)) return refuse_options(error, "load_factor must be finite");
  if (!(max_seconds >= 0.0 && std::isfinite(max_seconds)))
    return refuse_options(error, "max_seconds must be 0 (no budget) or positive and finite");
  return true;
}

ModalResult solve_modal(const Model& model, const ModalOptions& options, Data& data) {
  const auto start = Clock::now();
  ModalResult result;
  if (!options.IsValid(&result.message)) {
    result.message = "invalid modal options: " + result.message;
    return result;
  }
  const Deadline budget(start, options.max_seconds);
  try {
    compute_wrenches(model, data, options.time, options.load_factor);
    compute_tangent(model, data, options.time, false, options.load_factor);
    const SparseMatrix m = mass_matrix(model, data);
    // The symmetric part of K = -S, and the asymmetry of the mass-normalized operator (1/s^2 in
    // every entry: a plain norm of K mixes N/m with N m, so its value would depend on the unit of
    // length), block by block from the tangent's blocks and their transposes: no sparse
    // transposes or sums (a 100,000-body chain has 1e7 entries).
    const SparseMatrix sym = symmetric_stiffness(
        model, data, Eigen::VectorXd(m.diagonal()).cwiseSqrt().cwiseInverse(), &result.asymmetry);
    budget.check();
    const int wanted = std::max(1, options.modes), guard = options.guard_modes;
    const Eigen::Index n = model.n_dofs;
    result.shift = choose_shift(model, sym, m);
    // Torques of fixed direction and follower loads make the loaded state non-conservative and K
    // non-symmetric
    // at equilibrium: its own eigenproblem then, never its symmetric part (a cantilever bent by
    // a tip torque: 3.485 Hz from the symmetric part, 3.645 Hz from the non-symmetric problem
    // and from a transient). Rounding leaves ~1e-15.
    const bool nonsymmetric = result.asymmetry > kModalAsymmetryLimit;
    // Shift-invert asks for the wanted modes plus room for rigid ones: none when every body is
    // held by beams (mu = 0: no mode deforms no element), else 12 more at first. Below twice
    // that many degrees of freedom (Lanczos's subspace, 2 pairs + 1, would not fit) the dense
    // solver, whatever was asked.
    const Eigen::Index first_extra = result.shift == 0.0 && !nonsymmetric ? 0 : 12;
    const Eigen::Index lanczos_pairs = wanted + first_extra;
    const bool dense =
        options.solver == EigenSolverKind::kDense ||
        (options.solver == EigenSolverKind::kAuto && modal_dense_is_faster(n, lanczos_pairs)) ||
        n < 2 * lanczos_pairs || n < 3;
    const ElementDeformation deformation(model, data);

    SparseMatrix k;
    if (nonsymmetric) k = -stiffness_matrix(model, data);
    int complex_pairs = 0;
    double growth = 0.0;
    int found = 0;  // non-rigid modes among the pairs computed
    if (dense) {
      Eigenpairs pairs;
      if (nonsymmetric ? !solve_nonsymmetric(k, m, result.shift, n, true, budget, pairs,
                                             &complex_pairs, &growth)
                       : !solve_dense(sym, m, result.shift, pairs))
        throw std::runtime_error("the dense eigensolver failed");
      budget.check();
      found = classify(pairs, m, deformation, result.shift, wanted + guard, result);
      result.solver = "dense";
    } else {
      // The topology's fill-reducing ordering of K + mu M (K's pattern), made by the first
      // design that asks and shared by the others.
      std::shared_ptr<const SymmetricOrdering> ordering;
      if (!nonsymmetric && options.structure_cache)
        ordering = options.structure_cache->ordering(model, sym);
      // Rigid modes take places among the pairs nearest the shift: ask for more until enough
      // non-rigid ones are among them or every pair is.
      for (Eigen::Index extra = first_extra;; extra = std::max<Eigen::Index>(12, 4 * extra)) {
        const Eigen::Index count = std::min<Eigen::Index>(n - 1, wanted + guard + extra);
        Eigenpairs pairs;
        if (nonsymmetric
                ? !solve_nonsymmetric(k, m, result.shift, count, false, budget, pairs,
                                      &complex_pairs, &growth)
                : !solve_lanczos(sym, m, result.shift, count, ordering.get(), budget, pairs))
          throw std::runtime_error(nonsymmetric
                                       ? "the shift-invert eigensolver (Arnoldi) did not converge"
                                       : "the shift-invert eigensolver did not converge");
        found = classify(pairs, m, deformation, result.shift, wanted + guard, result);
        if (found >= wanted + guard || count >= n - 1 || complex_pairs > 0) break;
      }
      result.solver = "shift-invert";
    }
    result.nonsymmetric = nonsymmetric;
    if (complex_pairs > 0) {
      char growth_text[64];
      std::snprintf(growth_text, sizeof growth_text, "%.2g", growth);
      throw std::runtime_error(
          "the configuration flutters: " + std::to_string(complex_pairs) +
          " pair(s) of complex eigenvalues (|Im w^2| / |w^2| up to " + growth_text +
          "), vibrations that grow: the loads without a potential (torques of fixed direction, "
          "follower loads) feed them energy");
    }
    // The guard's modes leave the result's before anything reads them.
    {
      std::vector<Mode> kept;
      int elastic = 0;
      for (Mode& mode : result.modes)
        (mode.kind != Mode::Kind::kRigid && ++elastic > wanted ? result.guard : kept)
            .push_back(std::move(mode));
      result.modes = std::move(kept);
    }
    result.ok = true;
    participations(model, data, m, result);
    // Elastic modes that deform joints and no beam or rail: the joints' penalty stiffness, not the
    // structure, sets their frequencies (they rise as relative_compliance falls).
    if (!model.joints.empty()) {
      int penalty_modes = 0, elastic_number = 0, first_penalty = 0;
      double first_hz = 0.0;
      for (const Mode& mode : result.modes) {
        if (mode.kind == Mode::Kind::kRigid) continue;
        ++elastic_number;
        if (deformation.element_ratio(mode.shape) > kRigidModeDeformation) continue;
        if (penalty_modes++ == 0) first_penalty = elastic_number, first_hz = mode.frequency_hz;
      }
      if (penalty_modes > 0)
        result.warnings.push_back(
            std::to_string(penalty_modes) + " elastic mode(s) deform joints and no beam or rail " +
            "(the first: mode " + std::to_string(first_penalty) + ", " + hz_text(first_hz) + ")" +
            ": the joints' penalty stiffness sets their frequencies (they rise as the joints' "
            "relative_compliance falls), not the structure");
    }
    if (options.keep_mass) result.mass = m;
    // Resolution of each non-rigid mode against the rounding of the stiffness terms.
    const auto abs_times = [&sym](const Eigen::VectorXd& x) {
      Eigen::VectorXd out = Eigen::VectorXd::Zero(x.size());
      for (Eigen::Index c = 0; c < sym.outerSize(); ++c)
        for (SparseMatrix::InnerIterator it(sym, c); it; ++it)
          out(it.row()) += std::abs(it.value()) * std::abs(x(c));
      return out;
    };
    const Eigen::VectorXd weight = Eigen::VectorXd(m.diagonal()).cwiseSqrt().cwiseInverse();
    double worst = 0.0;
    int worst_mode = 0, number = 0;
    for (Mode& mode : result.modes) {
      if (mode.kind == Mode::Kind::kRigid) continue;
      ++number;
      mode.noise = std::numeric_limits<double>::epsilon() *
                   weight.cwiseProduct(abs_times(mode.shape)).norm() / std::abs(mode.eigenvalue);
      if (!(mode.noise <= worst)) worst = mode.noise, worst_mode = number;
    }
    const bool joints = !model.joints.empty();
    const std::string noise_text =
        "mode " + std::to_string(worst_mode) + ": the rounding of the stiffness terms reaches " +
        std::to_string(worst) + " of its inertia forces (" +
        (joints ? "joints' penalty stiffness far above the structure's (a larger "
                  "relative_compliance lowers it), or "
                : "") +
        "chains of very many short segments span more decades of stiffness than double "
        "precision holds)";
    if (!(worst <= kModalNoiseLimit)) {
      result.ok = false;
      result.message = "the modes are not resolved in double precision: " + noise_text +
                       "; use fewer segments" +
                       (joints ? " or a larger relative_compliance of the joints" : "");
    } else if (worst > kModalNoiseWarning) {
      char digits[96];
      std::snprintf(digits, sizeof digits, "the frequencies are resolved to ~%.0e only: ",
                    (joints ? kModalNoiseErrorJoints : kModalNoiseError) * worst);
      result.warnings.push_back(digits + noise_text);
    }
    if (result.ok && found < wanted) {
      result.ok = false;
      result.message = "asked for " + std::to_string(wanted) + " elastic mode" +
                       (wanted == 1 ? "" : "s") + ", but the scene has " +
                       (found == 0 ? std::string("none") : "only " + std::to_string(found)) +
                       ": its " + std::to_string(n) + " degrees of freedom include " +
                       std::to_string(result.rigid_modes) +
                       " rigid-body or mechanism mode(s), which deform no element";
    }
    // A rigid mode's eigenvalue is 0 up to the rounding of the stiffness, ~eps lambda_max (a
    // floating pair of bodies off the axes: -4e-9 1/s^2 beside lambda_max = 1.7e7); the shift is
    // 1e4 eps times the stiffness scale, so a tenth of it stays clear of that rounding while an
    // inverted pendulum's -g/l is far below it.
    int unstable = 0;
    for (const Mode& mode : result.modes)
      unstable += mode.eigenvalue < 0.0 &&
                  (mode.kind != Mode::Kind::kRigid || mode.eigenvalue < -0.1 * result.shift);
    if (unstable > 0 && result.ok) {
      result.ok = false;
      result.message =
          "the configuration is not a stable equilibrium: " + std::to_string(unstable) +
          " mode(s) with negative stiffness (buckling, or an unstable equilibrium)";
    }
    // What the beam law leaves out of the elements' own axial forces, per mode
    // (core/analysis/axial_force_check.hpp).
    if (result.ok) {
      const MissingAxialForces missing(model, data);
      std::vector<Eigen::VectorXd> shapes;
      std::vector<double> eigenvalues;
      for (const Mode& mode : result.modes) {
        shapes.push_back(mode.kind == Mode::Kind::kElastic ? mode.shape : Eigen::VectorXd());
        eigenvalues.push_back(mode.kind == Mode::Kind::kElastic ? mode.eigenvalue : 0.0);
      }
      if (std::string w = modal_axial_force_warning(missing, shapes, eigenvalues); !w.empty())
        result.warnings.push_back(std::move(w));
    }
    if (result.ok && nonsymmetric && !loaded_nonconservatively(model, options))
      result.warnings.push_back(
          "the tangent stiffness is not symmetric (relative asymmetry " +
          std::to_string(result.asymmetry) +
          ") although no torque or follower load loads the scene: the configuration is not an "
          "equilibrium");
  } catch (const DeadlinePassed&) {
    result.ok = false;
    result.timed_out = true;
    result.modes.clear();
    result.message = "the modal analysis did not finish within its time budget";
  } catch (const std::exception& e) {
    result.ok = false;
    result.message = e.what();
  }
  result.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

}  // namespace beamrail
