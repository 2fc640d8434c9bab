// The modes above a band-limited modal run's band (core/analysis/modal_integrator.hpp), kept
// quasi-static: the physical offsets are x = Phi z + y, y M0-orthogonal to the m modes kept and
// such that the accelerations have no part outside the band. y is found by the Newton iteration
// y <- y + R M0 a(Phi z + y), R = (K0 + mu M0)^-1 - Phi (Lambda + mu)^-1 Phi^T the residual
// flexibility (mu = 1e-2 of the band's top w^2 keeps rigid and mechanism modes, which lie in the
// band, from making it singular): one sparse LDL^T at set-up, and per correction one solve and one
// product with Phi. Where the motion turns stiff members, K0 is a poor Newton matrix for the modes
// above the band (update_tangent: the tangent of a later state, K^-1 and the Schur complement
// Psi^T K^-1 Psi keep Psi^T dy = 0).
//
// It also keeps what the method leaves out with their dynamics: the velocities of y (the rate at
// the accepted state, for a run handed on to another method) and their kinetic energy against the
// band's (QuasiStaticInertia). What the linear estimate of the band (modal_band.hpp) leaves out is
// the part the motion drives at second order, a stiff mode pulled along by the deflection (a heavy
// tip's axial motion as a cantilever bends: its inertia stiffens the bending). Dropped, the
// motion's frequencies are off by half the ratio of that energy to the band's (Rayleigh's
// quotient), and its phase drifts by that times w t. After each accepted step: the largest
// |dy/dt|^2_M0 (from y at the step's start and at its last stage) and the largest |nu|^2 (twice
// the band's kinetic energy); half their ratio times the lowest elastic w in the band times the
// time run (at least 1) estimates the drift relative to the motion (inertia()); above rtol the run
// warns. Under a harmonic load the motion goes at the load's frequency too, and its phase drifts
// at that rate: w is then at least the load's (set_forcing_rate). A 1.5 m cantilever of 20 x 10
// mm steel in 30 segments with a 0.3 kg tip under 5 N at 60 Hz (f1 about 2.5 Hz), bands of 1,050
// and 3,000 Hz, 0.3 s: 5.9e-5 and 4.3e-5 of the motion off, estimated at 5.8e-6 and 2.8e-6 with
// the lowest w (docs/transient_measurements.md "The quasi-static modes' inertia under a harmonic
// load"). Keeping those modes' inertia instead (y's second difference subtracted in the iteration)
// was tried: lagged, it drove the modes above the band and the runs diverged or erred more.
#pragma once

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <cmath>

#include "core/analysis/modal_integrator.hpp"

namespace beamrail {

class QuasiStaticModes {
 public:
  // With the symmetric stiffness K0 and the mass M0 of the linearization, the band's
  // M0-normalized modes Phi (n x m) and their w^2, and the band's top w^2: factorizes K0 + mu M0.
  // False when that is not positive definite (a mode of negative stiffness below the band's).
  // m0 and phi are kept by reference: they must outlive this object.
  bool init(const Eigen::SparseMatrix<double>& k0, const Eigen::SparseMatrix<double>& m0,
            const Eigen::MatrixXd& phi, const Eigen::ArrayXd& lambda, double top);

  // One Newton correction dy = R M0 a for the accelerations a (m0_a = M0 a; psi_a = Phi^T M0 a),
  // added to y; returns dy (valid until the next call).
  const Eigen::VectorXd& correct(const Eigen::VectorXd& m0_a, const Eigen::VectorXd& psi_a);

  // The Newton matrix from the tangent k = -d(M0 a)/dx of a later state (not symmetric where
  // the offsets' rotations are not the tangent's increments: ModalCoordinates::increment_maps);
  // false when k + mu M0 is singular.
  bool update_tangent(const Eigen::SparseMatrix<double>& k);

  // Whether the Newton matrix is a later tangent's (update_tangent), and back to K0's.
  bool updated() const { return updated_; }
  void reset_tangent() { updated_ = false; }

  // The quasi-static part of the latest evaluation.
  Eigen::VectorXd& y() { return y_; }
  const Eigen::VectorXd& y() const { return y_; }

  // A step's bookkeeping: y at the accepted state before its trials, and restored before each.
  void begin_step() { y_start_ = y_; }
  void restore() { y_ = y_start_; }

  // y at the accepted state the step began from (begin_step).
  const Eigen::VectorXd& step_start() const { return y_start_; }

  // After a step of size h is accepted, y being its last stage's (c h into it): the largest
  // kinetic energies of y and of the band's velocities nu so far, and what rate() needs. y's
  // kinetic energy counts only where `resolved`: its change over the step stands above the
  // iteration's noise (on a step of 1e-11 s that noise over the step is no velocity).
  void accepted(double h, double c, const Eigen::Ref<const Eigen::VectorXd>& nu, bool resolved);
  // After a restart: no step since.
  void restart() {
    last_step_ = 0.0;
    rate_known_ = false;
  }
  // dy/dt at the accepted state, from y at the last step's start, at its last stage and at its
  // end (y, converged since): the derivative of the parabola through them, second order in h.
  // Unknown (rate_known() false) before a step.
  void compute_rate();
  bool rate_known() const { return rate_known_; }
  const Eigen::VectorXd& rate() const { return y_rate_; }

  // The highest harmonic load's angular frequency [rad/s] (0: none), for inertia().
  void set_forcing_rate(double w) { forcing_rate_ = w; }
  // What leaving out y's kinetic energy does after `elapsed` seconds of the run (above). Its
  // ratio is at least the pull measured at the start (set_pull).
  QuasiStaticInertia inertia(double band_hz, double t, double elapsed) const;
  // The ratio of y's change to the band's, |dy|^2_M0 / |Phi dz|^2_M0, when the band moves from
  // the run's start to its static response there (ModalExponential::measure_pull): the kinetic
  // energy y would carry against the band's, as they move together.
  void set_pull(double ratio) { pull_ = ratio; }
  // Whether the band's slowest elastic mode (or the motion at a harmonic load's frequency, when
  // faster) has turned `angle` rad in `elapsed` seconds.
  bool settled(double elapsed, double angle) const {
    return !(lowest_elastic_ > 0.0) ||
           std::max(std::sqrt(lowest_elastic_), forcing_rate_) * elapsed >= angle;
  }

 private:
  const Eigen::SparseMatrix<double>* m0_ = nullptr;
  const Eigen::MatrixXd* phi_ = nullptr;
  Eigen::ArrayXd lambda_;
  double shift_ = 0.0;                                     // mu [1/s^2]
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> k0_;  // of K0 + mu M0
  Eigen::SparseLU<Eigen::SparseMatrix<double>> tangent_;   // of a later K + mu M0
  bool updated_ = false;      // tangent_ holds a later tangent (then kinv_psi_, schur_)
  Eigen::MatrixXd kinv_psi_;  // K^-1 Psi
  Eigen::PartialPivLU<Eigen::MatrixXd> schur_;  // of Psi^T K^-1 Psi
  Eigen::VectorXd y_, dy_, y_start_;
  Eigen::VectorXd work_n_, work_m_, psi_dy_, m0_dy_;
  // The last accepted step's y at its start and at its last stage, and its size (0: none since
  // the start or a restart); the rate of y at the accepted state when rate_known_.
  Eigen::VectorXd y_begin_, y_stage_, y_rate_;
  double last_step_ = 0.0;
  double last_stage_ = 0.5;  // where the last accepted step's last stage lay, c of c h
  bool rate_known_ = false;
  double kinetic_ = 0.0;          // the largest |dy/dt|^2_M0 so far
  double band_kinetic_ = 0.0;     // and |nu|^2
  double pull_ = 0.0;             // set_pull
  double lowest_elastic_ = -1.0;  // the lowest elastic w^2 in the band (-1: none)
  double forcing_rate_ = 0.0;     // the highest harmonic load's w [rad/s]
};

}  // namespace beamrail
