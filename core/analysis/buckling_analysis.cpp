#include "core/analysis/buckling_analysis.hpp"

#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsSolver.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/analysis/axial_force_check.hpp"
#include "core/analysis/buckling_path.hpp"
#include "core/analysis/deadline.hpp"
#include "core/analysis/dense_eigen.hpp"
#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"
#include "core/model/rotation.hpp"

namespace beamrail {
namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;
using Clock = std::chrono::steady_clock;

// The larger step of the differences along u1: the largest rotation (or displacement over the
// characteristic length) h u1 causes. Halved once for the extrapolation. Measured on a 20-segment
// clamped-free column under an axial and a lateral load: the factors from steps 1e-2 and 1e-3
// agree to 1.3e-10; smaller steps scatter by rounding (1e-4: 4e-9, 1e-5: 2e-9).
constexpr double kStep = 1e-3;

std::string text(const char* pattern, double x) {
  char buf[400];
  std::snprintf(buf, sizeof buf, pattern, x);
  return buf;
}

// The Cholesky factors of the reference stiffness K0 = P^T L L^T P for Spectra's Cholesky mode
// (the same factors solve for u1).
class CholeskyOp {
 public:
  using Scalar = double;
  explicit CholeskyOp(const Eigen::SimplicialLLT<SparseMatrix>& llt, Eigen::Index n)
      : llt_(llt), n_(n) {}
  Eigen::Index rows() const { return n_; }
  Eigen::Index cols() const { return n_; }
  void lower_triangular_solve(const double* x, double* y) const {
    Eigen::Map<Eigen::VectorXd> out(y, n_);
    out = llt_.permutationP() * Eigen::Map<const Eigen::VectorXd>(x, n_);
    llt_.matrixL().solveInPlace(out);
  }
  void upper_triangular_solve(const double* x, double* y) const {
    Eigen::Map<Eigen::VectorXd> out(y, n_);
    out = llt_.matrixU().solve(Eigen::Map<const Eigen::VectorXd>(x, n_));
    out = llt_.permutationPinv() * out;
  }

 private:
  const Eigen::SimplicialLLT<SparseMatrix>& llt_;
  Eigen::Index n_;
};

// x = -K1, for Spectra: A x with a deadline check per product.
class ProductOp {
 public:
  using Scalar = double;
  ProductOp(const SparseMatrix& a, const Deadline& deadline) : a_(a), deadline_(deadline) {}
  Eigen::Index rows() const { return a_.rows(); }
  Eigen::Index cols() const { return a_.cols(); }
  void perform_op(const double* x, double* y) const {
    deadline_.check();
    Eigen::Map<Eigen::VectorXd>(y, a_.rows()) =
        a_ * Eigen::Map<const Eigen::VectorXd>(x, a_.cols());
  }

 private:
  const SparseMatrix& a_;
  const Deadline& deadline_;
};

struct Saved {
  std::vector<Pose<double>> pose;
  std::vector<Vec4> q;
  std::vector<Vec3> rotation;
};

// The element part of the tangent S = d wrench / dX (blocks) at the reference moved by h u1.
std::vector<Mat6> element_tangent_at(const Model& model, Data& data, const Saved& reference,
                                     const Eigen::VectorXd& u1, double h, double t) {
  data.pose = reference.pose;
  data.q = reference.q;
  data.rotation = reference.rotation;
  apply_increment(model, data, h * u1);
  compute_tangent(model, data, t, false, 0.0);
  return data.stiffness;
}

// The most strain or rotation per unit load factor (motion_scale of u1 = K0^-1 P1) a buckling
// analysis takes: factors below its inverse are refused (their stress stiffness overflows).
constexpr double kMostMotionPerFactor = 1e100;

// The largest rotation, or displacement over `length`, of a motion x (dim n_dofs).
double motion_scale(const Eigen::VectorXd& x, double length) {
  double s = 0.0;
  for (Eigen::Index i = 0; i < x.size(); ++i)
    s = std::max(s, std::abs(x(i)) / ((i % kDofsPerBody) < 3 ? length : 1.0));
  return s;
}

// The shape scaled so that its largest translation or rotation x length is 1, that entry
// positive.
Eigen::VectorXd normalized_shape(Eigen::VectorXd x, double length) {
  double best = 0.0;
  Eigen::Index at = 0;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    const double v = std::abs(x(i)) * ((i % kDofsPerBody) < 3 ? 1.0 : length);
    if (v > best) best = v, at = i;
  }
  if (best > 0.0) x *= (x(at) < 0.0 ? -1.0 : 1.0) / best;
  return x;
}

// The positive eigenvalues mu = 1 / lambda of -K1 x = mu K0 x (all of them), with vectors.
void solve_dense(const SparseMatrix& a, const SparseMatrix& k0, Eigen::VectorXd& mu,
                 Eigen::MatrixXd& vectors) {
  const Eigen::MatrixXd ad(a), bd(k0);
  if (!generalized_symmetric_eigen(ad, bd, mu, vectors))
    throw std::runtime_error("the dense eigensolver failed");
}

}  // namespace

double buckling_factor(const BucklingResult& result, int k) {
  if (k < 1 || k > static_cast<int>(result.modes.size()))
    return std::numeric_limits<double>::infinity();
  return result.modes[k - 1].factor;
}

BucklingMatrices buckling_matrices(const Model& reference, const Model& scaled, double t,
                                   Data& data, bool symmetric_reference) {
  BucklingMatrices out;
  const double length = characteristic_length(reference);
  if (reference.n_dofs == 0) throw std::runtime_error("the scene has no free body");

  // K0: the tangent at the reference, with the constant loads' stiffness.
  compute_tangent(reference, data, t, false, 1.0);
  double asymmetry = 0.0;
  out.k0 = symmetric_stiffness(reference, data, stiffness_weights(reference, data), &asymmetry);
  if (symmetric_reference && asymmetry > kModalAsymmetryLimit)
    throw std::runtime_error(
        text("the reference state's tangent stiffness is not symmetric (relative asymmetry "
             "%.2g): torques of fixed direction or follower loads load it, which are not "
             "conservative; linear buckling does not apply (a static analysis's stability check "
             "does)",
             asymmetry));
  // The scaled loads at the reference, P1 (generalized forces, dim n_dofs).
  for (Vec6& w : data.wrench) w.setZero();
  add_load_wrenches(scaled, data, t, 1.0);
  const Eigen::VectorXd p1 = wrench_vector(scaled, data);
  if (!(p1.lpNorm<Eigen::Infinity>() > 0.0))
    throw std::runtime_error("the loads to scale are zero at the loads' time: nothing buckles");
  for (const Load& load : scaled.loads) {
    if (is_conservative(load) || load.time(t) * load.value == Vec3::Zero()) continue;
    if (!load.follows)
      throw std::runtime_error(
          "a torque of fixed direction is among the loads to scale: it is not conservative; "
          "linear buckling does not apply (a static analysis's stability check does)");
    // Beck's column (a tangential tip force) has no buckling load at all: it flutters.
    throw std::runtime_error(
        "a follower load is among the loads to scale: it is not conservative and may lose "
        "stability by flutter, which linear buckling cannot find; use a modal analysis about the "
        "static equilibrium (it fails where vibrations grow) or a static analysis's stability "
        "check at the loads of interest");
  }

  // With joints, a tangent that does not factorize or solve may be a held structure whose
  // joints' penalty double precision cannot resolve against it: a column between revolute
  // joints of relative_compliance 1e-9 was refused as "a body or mechanism free to move" (an
  // adversarial review, 2026-12-01; at 1e-6 its factor is 1.013 times Euler's).
  const std::string or_penalty =
      reference.joints.empty()
          ? ""
          : "; or the joints' penalty stiffness is beyond what double precision resolves "
            "against the structure (a relative_compliance far below the default 1e-6: raise it)";
  out.llt = std::make_shared<Eigen::SimplicialLLT<SparseMatrix>>(out.k0);
  if (out.llt->info() != Eigen::Success)
    throw std::runtime_error(
        "the reference state's tangent stiffness is not positive definite: a body or "
        "mechanism is free to move (a free body, or a carriage free along its rails), or the "
        "constant loads already buckle the structure; buckling needs every body held" +
        or_penalty);
  const Eigen::VectorXd u1 = out.llt->solve(p1);
  if (!u1.allFinite() || !((out.k0 * u1 - p1).norm() <= 1e-6 * p1.norm()))
    throw std::runtime_error(
        "the reference state's tangent stiffness is singular (a body or mechanism free to "
        "move): buckling needs every body held" +
        or_penalty);

  // Loads that move the structure by more than kMostMotionPerFactor per unit factor (a factor
  // below its inverse) overflow the stress stiffness's products in double precision: 1e200 N on a
  // column gave no factor (infinite: "they compress too little"), with status ok, where 1e100 N
  // gives the Euler load over the load to the digit (an adversarial review, 2026-12-01).
  if (!(motion_scale(u1, length) <= kMostMotionPerFactor))
    throw std::runtime_error(
        text("the scaled loads reach beyond double precision: per unit factor they would strain "
             "or turn the structure by %.2g, so the factor is below 1e-100, which the analysis "
             "cannot resolve; scale the loads down",
             motion_scale(u1, length)));
  // K1 = d K / d lambda: the element tangent's central differences along u1 at steps h and
  // h / 2, extrapolated, plus the load stiffness's change (exact).
  const double h = kStep / std::max(motion_scale(u1, length), 1e-300);
  const Saved saved{data.pose, data.q, data.rotation};
  std::vector<Mat6> d1(data.stiffness.size()), d2(data.stiffness.size());
  {
    const auto plus = element_tangent_at(reference, data, saved, u1, h, t);
    const auto minus = element_tangent_at(reference, data, saved, u1, -h, t);
    const auto half_plus = element_tangent_at(reference, data, saved, u1, 0.5 * h, t);
    const auto half_minus = element_tangent_at(reference, data, saved, u1, -0.5 * h, t);
    for (size_t b = 0; b < d1.size(); ++b)
      d1[b] = (4.0 * (half_plus[b] - half_minus[b]) / h - (plus[b] - minus[b]) / (2.0 * h)) / 3.0;
  }
  data.pose = saved.pose;
  data.q = saved.q;
  data.rotation = saved.rotation;
  // Forces at body points: d/dlambda of [F]x [R]x, the constant loads' levers turning with
  // u1's rotation theta (dR = theta x R), the scaled loads' own values.
  const auto add_load_part = [&](const Model& m, bool turning) {
    for (const Load& load : m.loads) {
      const int k = m.bodies[load.body].free_index;
      if (k < 0 || !is_conservative(load)) continue;  // refused above
      const Vec3 force = load.time(t) * load.value;
      const Vec3 lever = data.pose[load.body].A * load.offset;
      const Vec3 theta = u1.segment<3>(kDofsPerBody * k + 3);
      d1[k].block<3, 3>(3, 3) += turning
                                     ? Mat3(skew<double>(force) * skew<double>(theta.cross(lever)))
                                     : Mat3(skew<double>(force) * skew<double>(lever));
    }
  };
  add_load_part(reference, true);
  add_load_part(scaled, false);
  d2.swap(data.stiffness);
  data.stiffness = d1;
  out.k1 = symmetric_stiffness(reference, data, stiffness_weights(reference, data), &out.asymmetry);
  data.stiffness.swap(d2);  // K0's blocks again
  out.u1 = u1;
  return out;
}

namespace {

bool refuse_options(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

}  // namespace

bool BucklingOptions::IsValid(std::string* error) const {
  if (modes < 1) return refuse_options(error, "modes must be at least 1");
  if (guard_modes < 0) return refuse_options(error, "guard_modes must be at least 0");
  if (std::isnan(time)) return refuse_options(error, "time must be a number");
  if (!(max_seconds >= 0.0 && std::isfinite(max_seconds)))
    return refuse_options(error, "max_seconds must be 0 (no budget) or positive and finite");
  return true;
}

BucklingResult solve_buckling(const Model& reference, const Model& scaled,
                              const BucklingOptions& options, Data& data) {
  const auto start = Clock::now();
  BucklingResult result;
  if (!options.IsValid(&result.message)) {
    result.message = "invalid buckling options: " + result.message;
    return result;
  }
  const Deadline deadline(start, options.max_seconds);
  try {
    const double t = options.time;
    const double length = characteristic_length(reference);
    const Eigen::Index n = reference.n_dofs;
    const BucklingMatrices matrices = buckling_matrices(reference, scaled, t, data);
    // What the beam law leaves out of the elements' own axial forces, at the reference state
    // and per unit factor (core/analysis/axial_force_check.hpp).
    const MissingAxialForces missing_reference(reference, data);
    const MissingAxialForces missing_per_factor(reference, data, matrices.u1);
    std::vector<Eigen::VectorXd> shapes;
    std::vector<double> factors, stiffness;
    if (!held_by_beams(reference)) {
      // Rails and free bodies may leave directions without stiffness that a Cholesky factor
      // still passes at rounding level: those have no modes of their own to lose.
      ModalOptions check;
      check.modes = 1;
      check.time = t;
      check.max_seconds = options.max_seconds;
      Data copy = data;
      const ModalResult modes = solve_modal(reference, check, copy);
      if (modes.rigid_modes > 0)
        throw std::runtime_error(
            std::to_string(modes.rigid_modes) +
            " direction(s) of the reference state deform no element (a free body, or a "
            "carriage free along its rails): buckling needs every body held");
    }
    deadline.check();
    result.step = kStep;
    result.asymmetry = matrices.asymmetry;
    const SparseMatrix& k0 = matrices.k0;
    const Eigen::SimplicialLLT<SparseMatrix>& llt = *matrices.llt;
    const SparseMatrix minus_k1 = -matrices.k1;
    const char* beyond_precision =
        "the scaled loads reach beyond double precision: the stiffness they cause is not finite; "
        "scale the loads down";
    // Loads of 1e200 N and more overflow the stress stiffness they cause: its entries and the
    // factors would be inf or NaN, read as "no factor" (infinite, the structure unbuckled; an
    // adversarial review, 2026-12-01).
    const auto finite = [](const SparseMatrix& a) {
      return Eigen::Map<const Eigen::VectorXd>(a.valuePtr(), a.nonZeros()).allFinite();
    };
    if (!finite(minus_k1) || !finite(k0) || !matrices.u1.allFinite())
      throw std::runtime_error(beyond_precision);

    // -K1 x = mu K0 x, mu = 1 / lambda: the largest positive mu are the lowest positive factors.
    const int wanted = std::max(1, options.modes);
    const bool dense =
        options.solver == EigenSolverKind::kDense ||
        (options.solver == EigenSolverKind::kAuto && buckling_dense_is_faster(n, wanted)) ||
        n < wanted + 24;
    Eigen::VectorXd mu;
    Eigen::MatrixXd vectors;
    if (dense) {
      solve_dense(minus_k1, k0, mu, vectors);
      result.solver = "dense";
    } else {
      CholeskyOp bop(llt, n);
      ProductOp aop(minus_k1, deadline);
      const Eigen::Index nev = std::min<Eigen::Index>(n - 1, wanted + options.guard_modes);
      const Eigen::Index ncv = std::min<Eigen::Index>(n, std::max<Eigen::Index>(2 * nev + 1, 20));
      Spectra::SymGEigsSolver<ProductOp, CholeskyOp, Spectra::GEigsMode::Cholesky> eigs(aop, bop,
                                                                                        nev, ncv);
      eigs.init();
      eigs.compute(Spectra::SortRule::LargestAlge, 1000, 1e-12);
      if (eigs.info() != Spectra::CompInfo::Successful)
        throw std::runtime_error(
            "the Lanczos iteration of the buckling eigenproblem did not converge");
      mu = eigs.eigenvalues();
      vectors = eigs.eigenvectors();
      result.solver = "lanczos";
    }
    if (!mu.allFinite()) throw std::runtime_error(beyond_precision);
    // Rounding leaves |mu| ~ 1e-16 max |mu| in directions the scaled loads do not stress: no
    // factor of their own.
    const double floor = 1e-12 * mu.cwiseAbs().maxCoeff();
    std::vector<Eigen::Index> order;
    for (Eigen::Index i = 0; i < mu.size(); ++i)
      if (mu(i) > floor) order.push_back(i);
    std::sort(order.begin(), order.end(),
              [&](Eigen::Index a, Eigen::Index b) { return mu(a) > mu(b); });
    // (Lanczos's count as without the guard: the factors it would have computed.)
    result.positive_factors = static_cast<int>(order.size());
    if (!dense) result.positive_factors = std::min(result.positive_factors, wanted);
    for (Eigen::Index i : order) {
      if (static_cast<int>(result.modes.size()) >= wanted) {
        if (static_cast<int>(result.guard.size()) >= options.guard_modes) break;
        result.guard.push_back({1.0 / mu(i), normalized_shape(vectors.col(i), length), 0.0});
        continue;
      }
      const double factor = 1.0 / mu(i);
      // How far the stiffness along the shape is from zero on the prebuckling path at the factor
      // (core/analysis/buckling_path.hpp): what the linearization in the load leaves out.
      const Eigen::VectorXd phi = vectors.col(i);
      const double nonlinearity =
          std::abs(
              phi.dot(path_stiffness_product(reference, scaled, t, data, matrices.u1, factor, phi)
                          .col(0))) /
          phi.dot(k0 * phi);
      deadline.check();
      shapes.push_back(phi);
      factors.push_back(factor);
      stiffness.push_back(phi.dot(k0 * phi));
      result.modes.push_back({factor, normalized_shape(phi, length), nonlinearity});
      const std::string mode_number =
          text("buckling mode %.0f: ", static_cast<double>(result.modes.size()));
      if (nonlinearity >= kBucklingNotALoad)
        result.warnings.push_back(
            mode_number +
            text("the factor %.6g is no buckling load: on the prebuckling path at that factor ",
                 factor) +
            text("the shape keeps %.2g of its stiffness, which the linearization in the load "
                 "loses (a beam bent by a load that compresses nothing gives such factors); a "
                 "static analysis with the loads at the factor tells whether the structure "
                 "buckles",
                 nonlinearity));
      else if (nonlinearity > kBucklingNonlinearityLimit)
        result.warnings.push_back(
            mode_number +
            text("the tangent stiffness changes with the prebuckling deformation beyond first "
                 "order: at the factor %.6g ",
                 factor) +
            text("the shape keeps %.2g of its stiffness on the prebuckling path, so the factor "
                 "may be off by about as much (segments short beside their section make this; "
                 "a static analysis with the loads near the factor tells)",
                 nonlinearity));
    }
    result.ok = true;
    if (std::string w = buckling_axial_force_warning(missing_reference, missing_per_factor, shapes,
                                                     factors, stiffness);
        !w.empty())
      result.warnings.push_back(std::move(w));
    if (result.positive_factors < wanted) {
      // A beam in one element has no stress stiffness of its own, so it buckles in no mode.
      std::string unsplit;
      for (size_t g = 0; g < missing_per_factor.beam_names().size() && unsplit.empty(); ++g)
        if (missing_per_factor.beam_elements()[g] == 1 && missing_per_factor.beam_forces()[g] < 0.0)
          unsplit = "; beam \"" + missing_per_factor.beam_names()[g] +
                    "\" is one element, which has no stress stiffness of its own and buckles "
                    "only as part of a chain (docs/model.md \"Axial force and bending\"): give "
                    "compressed beams \"segments\"";
      result.warnings.push_back(
          "the scaled loads buckle the structure in " + std::to_string(result.positive_factors) +
          " mode(s) only (" + std::to_string(wanted) +
          " asked for): they compress too little of it; the missing factors are infinite" +
          unsplit);
    }
  } catch (const DeadlinePassed&) {
    result.ok = false;
    result.timed_out = true;
    result.modes.clear();
    result.message = "the buckling analysis did not finish within its time budget";
  } catch (const std::exception& e) {
    result.ok = false;
    result.modes.clear();
    result.message = e.what();
  }
  result.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

}  // namespace beamrail
