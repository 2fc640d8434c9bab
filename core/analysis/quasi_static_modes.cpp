#include "core/analysis/quasi_static_modes.hpp"

#include <algorithm>
#include <cmath>

#include "core/analysis/dense_product.hpp"

namespace beamrail {
namespace {

// out -= a b for a vector b (one pass over a; work: a.rows() doubles of work space).
void subtract_product(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, Eigen::VectorXd& work,
                      Eigen::VectorXd& out) {
  work.resize(a.rows());
  multiply_vector(a, b.data(), work.data());
  out -= work;
}

}  // namespace

bool QuasiStaticModes::init(const Eigen::SparseMatrix<double>& k0,
                            const Eigen::SparseMatrix<double>& m0, const Eigen::MatrixXd& phi,
                            const Eigen::ArrayXd& lambda, double top) {
  m0_ = &m0;
  phi_ = &phi;
  lambda_ = lambda;
  for (Eigen::Index i = 0; i < lambda.size(); ++i)
    if (lambda(i) > 1e-12 * lambda.maxCoeff() &&
        (lowest_elastic_ < 0.0 || lambda(i) < lowest_elastic_))
      lowest_elastic_ = lambda(i);
  // Shifted by a hundredth of the band's w^2 so that rigid-body and mechanism modes (in the
  // band) leave it regular: the iteration's fixed point (no acceleration outside the band) is
  // the same; its contraction is at most shift_ / w^2 of the band.
  shift_ = 0.01 * top;
  k0_.compute(Eigen::SparseMatrix<double>(k0 + shift_ * m0));
  y_ = Eigen::VectorXd::Zero(phi.rows());
  return k0_.info() == Eigen::Success && (k0_.vectorD().array() > 0.0).all();
}

const Eigen::VectorXd& QuasiStaticModes::correct(const Eigen::VectorXd& m0_a,
                                                 const Eigen::VectorXd& psi_a) {
  if (updated_) {
    dy_ = tangent_.solve(m0_a);
    // With the tangent K of a later state: dy = K^-1 (M0 a - Psi l), Psi^T dy = 0.
    m0_dy_.noalias() = *m0_ * dy_;
    psi_dy_.resize(phi_->cols());
    multiply_transposed(*phi_, m0_dy_.data(), psi_dy_.data());
    work_m_ = schur_.solve(psi_dy_);
    subtract_product(kinv_psi_, work_m_, work_n_, dy_);
  } else {
    dy_ = k0_.solve(m0_a);
    work_m_ = psi_a.array() / (lambda_ + shift_);
    subtract_product(*phi_, work_m_, work_n_, dy_);
  }
  y_ += dy_;
  return dy_;
}

bool QuasiStaticModes::update_tangent(const Eigen::SparseMatrix<double>& k) {
  Eigen::SparseMatrix<double> shifted = k + shift_ * *m0_;
  shifted.makeCompressed();
  tangent_.compute(shifted);
  if (tangent_.info() != Eigen::Success) return false;
  const Eigen::MatrixXd psi = *m0_ * *phi_;
  kinv_psi_ = tangent_.solve(psi);
  if (!kinv_psi_.allFinite()) return false;
  schur_.compute(psi.transpose() * kinv_psi_);
  updated_ = true;
  return true;
}

void QuasiStaticModes::accepted(double h, double c, const Eigen::Ref<const Eigen::VectorXd>& nu,
                                bool resolved) {
  // y_ is the last stage's, at c h into the step.
  work_n_ = (y_ - y_start_) / (c * h);
  y_begin_ = y_start_;
  y_stage_ = y_;
  last_step_ = h;
  last_stage_ = c;
  rate_known_ = false;
  if (resolved) kinetic_ = std::max(kinetic_, work_n_.dot(*m0_ * work_n_));
  band_kinetic_ = std::max(band_kinetic_, nu.squaredNorm());
}

void QuasiStaticModes::compute_rate() {
  if (!(last_step_ > 0.0)) return;
  const double c = last_stage_, h = last_step_;
  y_rate_ = ((1.0 - c) / (c * h)) * y_begin_ - (1.0 / (c * (1.0 - c) * h)) * y_stage_ +
            ((2.0 - c) / ((1.0 - c) * h)) * y_;
  rate_known_ = true;
}

QuasiStaticInertia QuasiStaticModes::inertia(double band_hz, double t, double elapsed) const {
  QuasiStaticInertia q;
  q.band_hz = band_hz;
  q.t = t;
  q.ratio = pull_;
  if (band_kinetic_ > 0.0) q.ratio = std::max(q.ratio, kinetic_ / band_kinetic_);
  if (!(q.ratio > 0.0)) return q;
  const double w = std::max(std::sqrt(std::max(0.0, lowest_elastic_)), forcing_rate_);
  q.drift = 0.5 * q.ratio * std::max(1.0, w * elapsed);
  return q;
}

}  // namespace beamrail
