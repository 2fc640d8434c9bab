#include "core/analysis/modal_integrator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <numbers>

#include "core/analysis/deformation_check.hpp"
#include "core/analysis/dense_product.hpp"
#include "core/analysis/explicit_stability.hpp"
#include "core/analysis/exponential_step.hpp"
#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/modal_band.hpp"
#include "core/analysis/modal_coordinates.hpp"
#include "core/analysis/modal_reference.hpp"
#include "core/analysis/modal_step_bounds.hpp"
#include "core/analysis/quasi_static_modes.hpp"
#include "core/analysis/static_analysis.hpp"
#include "core/analysis/transient.hpp"
#include "core/model/dynamics.hpp"
#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"
#include "core/model/rotation.hpp"

namespace beamrail {

namespace {

constexpr int kD = kDofsPerBody;

using Block = ModeBlock;

// out = a b (a change of basis of both columns; a is n x n, or a band's n x m basis or its
// transpose).
void multiply(const Eigen::MatrixXd& a, const Block& b, Block& out) {
  out.resize(a.rows(), 2);
  multiply_pair(a, b.data(), out.data());
}

// set_inertia_limit applies from this angle of the band's slowest elastic mode on [rad].
constexpr double kInertiaSettling = 2.0;

enum Flag {
  kOk = 0,
  kTooManySteps = -1,
  kStepTooSmall = kModalStepTooSmall,
  kNonFinite = kModalNonFinite,
  kTooFar = kModalTooFar,
  kInertia = kModalInertia,
  kOutOfRange = kModalOutOfRange,
  kHeld = kModalHeld
};

class ModalExponential : public Integrator {
 public:
  bool init(const IntegratorOptions& o, OdeContext& c, N_Vector y0, std::string* error, double t0) {
    options_ = o;
    context_ = &c;
    t_ = t0;
    t0_ = t0;
    max_rotation_ = o.max_rotation > 0.0 ? o.max_rotation : kModalIntegratorMaxRotation;
    low_order_weight_ = std::pow(o.rtol, 0.25) / kLowOrderScale;
    const Model& model = c.model;
    n_ = model.n_dofs;
    if (n_ == 0) return fail(error, "the modal integrator needs at least one free body");
    if (!model.driven_bodies.empty())
      return fail(error, "body \"" + model.bodies[model.driven_bodies.front()].name +
                             "\" moves as prescribed: the modal method vibrates about one fixed "
                             "configuration; use bdf or dirk");
    band_hz_ = o.max_frequency_hz;
    if (n_ > kModalIntegratorMaxDofs && !(band_hz_ > 0.0) && !o.choose_band)
      return fail(error, "the modal integrator handles up to " +
                             std::to_string(kModalIntegratorMaxDofs / kD) + " free bodies (" +
                             std::to_string(model.n_free()) +
                             " here) unless band-limited (max_frequency_hz): use bdf or dirk "
                             "with the sparse solver");
    y13_.resize(model.n_states);
    watched_.resize(model.n_states);
    acceleration_.resize(n_);
    ydot13_.resize(model.n_states);
    const double* y = N_VGetArrayPointer(y0);
    std::vector<double> reference(y, y + model.n_states);
    if (!modal_reference(model, options_, *context_, reference, warnings, &initial_, error))
      return false;
    // The linearization: mass and symmetric tangent stiffness at the reference, at rest.
    Data& data = c.data;
    set_state(model, data, reference.data());
    compute_wrenches(model, data, c.force_time(t0));
    compute_tangent(model, data, c.force_time(t0), false);
    coordinates_.set_reference(model, reference.data());
    // A part of the scene that floats and spins: its reference turns with it
    // (modal_coordinates.hpp), when it turns more than kTurningFrameMinTurn by the end of the run
    // (1 s when the run gives no end): a part that barely turns, or not at all (an angular
    // velocity of rounding, 5e-11 rad/s on a moving pair of tiny inertias), is followed in fixed
    // axes, without the frame's step bound (that pair: 4 steps instead of a million).
    const double span = o.horizon > t0 ? o.horizon - t0 : 1.0;
    for (const std::vector<int>& part : floating_parts(model)) {
      const RigidMotion motion = rigid_motion(model, y, part);
      if (motion.angular_velocity.norm() * span > kTurningFrameMinTurn)
        coordinates_.set_turning_frame(t0, motion, part);
    }
    if (band_hz_ > 0.0 || o.choose_band) {
      if (!band_limited_basis(model, data, t0, y, error)) return false;
    } else {
      const Eigen::MatrixXd k = -Eigen::MatrixXd(stiffness_matrix(model, data));
      m0_ = mass_matrix(model, data);
      Eigen::VectorXd values;
      if (!solve_dense_eigenproblem(0.5 * (k + k.transpose()), Eigen::MatrixXd(m0_), values, phi_))
        return fail(error, "the modal integrator's eigensolver failed");
      blocks_.lambda = values.array();
      m_ = n_;
    }
    if (largest_damping(model) > 0.0 && !modal_damping(t0)) {
      *error = "the modal integrator: the damping forces at the linearization are not finite";
      return false;
    }
    order_.resize(blocks_.lambda.size());
    for (Eigen::Index i = 0; i < blocks_.lambda.size(); ++i) order_[i] = i;
    std::sort(order_.begin(), order_.end(), [&](Eigen::Index a, Eigen::Index b) {
      return blocks_.lambda[a] > blocks_.lambda[b];
    });
    // How far each mode moves the elements per unit of its coordinate, in length and angle.
    {
      Data at_reference(model);
      set_state(model, at_reference, reference.data());
      reach_ = element_reach(model, at_reference, phi_);
    }
    bounds_ = ModalStepBounds(
        o.rtol,
        blocks_.lambda.size() > 0 ? std::sqrt(std::max(blocks_.lambda.maxCoeff(), 0.0)) : 0.0,
        coordinates_.turning(), moves_as_mechanism(model), highest_harmonic_hz(model));
    from_states(y);
    linear_solver = "modal";
    band_hz = m_ < n_ ? band_hz_ : 0.0;
    stats_.jacobian_evaluations = 1;  // the tangent of the linearization
    return true;
  }

  int advance(double tout, double tstop, N_Vector y, double* t) override {
    const double target = std::min(tout, tstop);
    int flag = kOk;
    context_->nonfinite_evaluations = 0;  // out-of-range trial states in this call
    context_->out_of_range.clear();
    while (t_ < target && flag == kOk) {
      flag = step_towards(target);
      if (flag == kOk && inertia_limit_ > 0.0 && inertia_settled() &&
          quasi_static_inertia().drift > inertia_limit_)
        flag = kInertia;
      if (flag == kOk && held_limit_ > 0 && held_.held >= held_limit_) flag = kHeld;
    }
    // The quasi-static part of the state reported (kept for the next step), and its rate.
    if ((flag == kOk || flag == kInertia || flag == kHeld) && reduced_ && !have_n0_) {
      try {
        const int reached = flag;
        if (!nonlinear(t_, z_, x_, n0_, &flag)) flag = fail_flag(flag);
        have_n0_ = flag == kOk;
        if (have_n0_) {
          flag = reached;
          quasi_.compute_rate();
        }
      } catch (const std::exception& e) {
        context_->callback_error = e.what();
        flag = kNonFinite;
      }
    }
    to_states(N_VGetArrayPointer(y));
    *t = t_;
    return flag;
  }

  void restart(double t, N_Vector y) override {
    t_ = t;
    have_n0_ = false;
    starting_ = true;
    quasi_.restart();
    from_states(N_VGetArrayPointer(y));
  }

  SolverStats stats() const override { return stats_; }

  std::vector<MethodPhase> phases(long* count) const override {
    *count = band_estimate_ >= 0.0 ? 1 : 0;
    if (!*count) return {};
    return {MethodPhase{t0_, "modal", band_choice()}};
  }

  const InitialLinearization& initial_linearization() const { return initial_; }

  std::string band_choice() const {
    if (band_estimate_ < 0.0) return "";
    char text[240];
    if (m_ == n_)
      std::snprintf(text, sizeof text,
                    "every mode integrated: rtol needs %ld of the %ld (the modes above them ring "
                    "at most at rtol), where the full basis costs less than a band",
                    static_cast<long>(band_needed_), static_cast<long>(n_));
    else
      std::snprintf(text, sizeof text,
                    "band %.17g Hz chosen for rtol: %ld of %ld modes integrated, the others "
                    "quasi-static (their ringing estimated at %.2g of the motion)",
                    band_hz_, static_cast<long>(m_), static_cast<long>(n_), band_estimate_);
    return text;
  }

  const Eigen::ArrayXd& eigenvalues() const { return blocks_.lambda; }
  const Eigen::ArrayXd& damping() const { return blocks_.damping; }
  double damping_coupling() const { return damping_coupling_; }
  double step_size() const { return h_; }
  HeldSteps held_steps() const { return held_; }

  // The largest rotation of a body from the linearization at the accepted state [rad].
  double largest_rotation() const { return coordinates_.largest_rotation(x_); }

  // Whether the mechanism's step bound holds at the accepted state (z: the modes there, z_ or
  // with their ringing about the static state of the forces: ringing_about_static_state).
  bool mechanism_bound(const ModeBlock& z) const {
    return bounds_.mechanism > 0.0 &&
           (bounds_.hold_mechanism || modal_stiff_share(blocks_.lambda, z) > kMechanismStiffShare);
  }
  bool mechanism_bound() const { return mechanism_bound(z_); }
  void hold_mechanism_bound() { bounds_.hold_mechanism = true; }

  // The modes at the accepted state with their ringing about the static state of the forces
  // there (ringing_about_static_state), once the step's start has been evaluated: the
  // band-limited iteration left Phi^T M0 a in psi_a_; else M0 a is in m0_v_ (one more pass).
  const ModeBlock& start_ringing() {
    if (!reduced_) {
      psi_a_.resize(m_);
      multiply_transposed(phi_, m0_v_.data(), psi_a_.data());
    }
    start_ringing_ = ringing_about_static_state(blocks_.lambda, z_, psi_a_);
    return start_ringing_;
  }

  // The longest step, at most `h`, from the accepted state that no element crosses an edge of
  // its range or of its warnings unseen: the modes that could carry it there resolved
  // (kResolvedPhase / modal_edge_rate), the paths of the slow and rigid modes bounded
  // (modal_slow_edge_step). Either N at that state is in n0_, or (every mode integrated) M0 a is
  // in m0_v_ and a in acceleration_: there the modal accelerations cost a pass over Phi, taken
  // only when a bound on them (|psi_a_i| <= |a|_M0, the modes mass-normalized) does not already
  // rule the edges out (the braced tower: never).
  double edge_step(double h) {
    const ElementMargins margins = element_margins(context_->model, context_->data);
    if (margins.length.empty()) return h;
    const double length = *std::min_element(margins.length.begin(), margins.length.end());
    const double angle = *std::min_element(margins.angle.begin(), margins.angle.end());
    const Eigen::ArrayXd& lambda = blocks_.lambda;
    const auto damping = [this](Eigen::Index i) {
      return blocks_.damped() ? blocks_.damping[i] * z_(i, 1) : 0.0;
    };
    edge_psi_a_.resize(m_);
    if (have_n0_) {
      for (Eigen::Index i = 0; i < m_; ++i)
        edge_psi_a_[i] = n0_(i, 1) - lambda[i] * z_(i, 0) - damping(i);
    } else {
      const double a_norm = std::sqrt(std::max(acceleration_.dot(m0_v_), 0.0));
      double length_swing = 0.0, angle_swing = 0.0, length_drift = 0.0, angle_drift = 0.0;
      for (Eigen::Index i = 0; i < m_; ++i) {
        if (!(lambda[i] * h * h > kResolvedPhase * kResolvedPhase)) {
          length_drift += reach_.largest(i, 0) * a_norm;
          angle_drift += reach_.largest(i, 1) * a_norm;
        }
        if (!(lambda[i] > 0.0)) continue;
        const double swing =
            (a_norm + std::abs(damping(i))) / lambda[i] + std::abs(z_(i, 1)) / std::sqrt(lambda[i]);
        length_swing += reach_.largest(i, 0) * swing;
        angle_swing += reach_.largest(i, 1) * swing;
      }
      const double passed = h * h / 8.0;  // a parabola's excursion per unit acceleration
      if (!(length_swing > kEdgeShare * length) && !(angle_swing > kEdgeShare * angle) &&
          !(length_drift * passed > kSlowEdgeShare * length) &&
          !(angle_drift * passed > kSlowEdgeShare * angle))
        return h;
      multiply_transposed(phi_, m0_v_.data(), edge_psi_a_.data());
    }
    const Eigen::ArrayXd swing =
        modal_swing(lambda, blocks_.damped() ? blocks_.damping : Eigen::ArrayXd(), z_, edge_psi_a_);
    const double rate = modal_elements_edge_rate(lambda, order_, swing, reach_, margins.length,
                                                 margins.angle, kEdgeShare);
    if (rate > 0.0) h = std::min(h, kResolvedPhase / rate);
    return modal_slow_edge_step(lambda, edge_psi_a_, phi_, reach_, margins.length, margins.angle, h,
                                kSlowEdgeShare);
  }

  // The frequency of the mechanism's ringing modes at the accepted state [rad/s] (0: none).
  double ringing_rate(const ModeBlock& z) const {
    if (!(bounds_.mechanism_wh > 0.0)) return 0.0;
    return modal_ringing_rate(blocks_.lambda, order_, z, kMechanismRingingShare);
  }

  std::string failure(int flag) const override {
    if (context_->timed_out) return "timeout: the run exceeded its max_seconds budget";
    if (!context_->callback_error.empty())
      return "error while evaluating the model: " + context_->callback_error;
    switch (flag) {
      case kTooManySteps:
        return "too many steps (max_steps reached)";
      case kStepTooSmall:
        return "the step size fell below the roundoff of the time (the tolerances cannot be met)";
      case kNonFinite:
        return "the forces became non-finite (the motion diverged)";
      case kTooFar:
        return detail_;
      case kInertia:
        return quasi_static_inertia_warning(quasi_static_inertia());
      case kHeld: {
        char text[160];
        std::snprintf(text, sizeof text,
                      "the mechanism's bounds held %ld of its last %ld steps below %g of the step "
                      "its estimates asked for",
                      held_.held, held_.steps, kMechanismHeldShare);
        return text;
      }
      case kOutOfRange:
        if (!context_->divergence.empty()) return context_->divergence;  // between two steps
        return context_->out_of_range + " (the modal integrator could not step past it)";
      default:
        return "modal integrator flag " + std::to_string(flag);
    }
  }

 private:
  bool fail(std::string* error, const std::string& what) {
    *error = what;
    return false;
  }

  // The modes of the band (dense eigensolver up to kModalDenseBandMaxDofs, else shift-invert
  // Lanczos asked for more modes until one lies above the band or, when the band is chosen
  // (options_.choose_band, core/analysis/modal_band.hpp), until the band meets rtol) and, when
  // some lie above, the factored K0 of the static correction. The linearization is posed in
  // `data`; y0 is the initial state.
  bool band_limited_basis(const Model& model, Data& data, double t0, const double* y0,
                          std::string* error) {
    const bool choose = !(band_hz_ > 0.0);
    Eigen::SparseMatrix<double> k0 = -stiffness_matrix(model, data);
    k0 = 0.5 * Eigen::SparseMatrix<double>(k0 + Eigen::SparseMatrix<double>(k0.transpose()));
    m0_ = mass_matrix(model, data);
    std::vector<BandExcitation> excitations;
    const std::vector<int> watched = watched_bodies(model);
    {
      // What rings (for a chosen band's choice and a given one's estimate): the force out of
      // balance at the initial state (what makes an offset from the linearization ring; with the
      // kinematics of the motion, unlike the offset itself, whose second-order parts, such as a
      // bent beam's shortening, follow the bending instead) and its velocity.
      const Data linearized = data;
      Block x;
      coordinates_.offsets(t0, y0, x);
      const Eigen::VectorXd velocity = x.col(1);
      coordinates_.states(t0, x, y13_.data());  // with its velocities (gyroscopic forces, damping)
      if (!accelerations(t0, x))
        return fail(error, "the modal integrator: the forces at the initial state are not finite");
      data = linearized;
      excitations = band_excitations(model, data, m0_ * acceleration_, velocity, t0,
                                     options_.horizon > t0 ? options_.horizon - t0 : 0.0);
    }
    const double seconds =
        std::chrono::duration<double>(context_->deadline - std::chrono::steady_clock::now())
            .count();
    BandModes band;
    const double horizon = options_.horizon > t0 ? options_.horizon - t0 : 0.0;
    if (!solve_band_modes(model, data, t0, k0, m0_, choose ? 0.0 : band_hz_, excitations, watched,
                          options_.rtol, seconds, band, error, horizon))
      return false;
    m_ = band.kept;
    const double limit = band.top;
    if (choose) {
      band_hz_ = std::sqrt(limit) / (2.0 * M_PI);
      band_needed_ = band.needed;
      band_estimate_ = band.estimate;
    } else if (band.given_estimate > options_.rtol) {
      char text[500];
      std::snprintf(text, sizeof text,
                    "band-limited run (%.4g Hz): the modes above the band would ring with about "
                    "%.2g of the motion (estimated from the initial state and the loads' changes "
                    "as for a band chosen for rtol), above rtol; the run keeps them quasi-static "
                    "and leaves that out: a higher max_frequency_hz, \"auto\" (the band chosen "
                    "for rtol) or every mode",
                    band_hz_, band.given_estimate);
      warnings.push_back(text);
    }
    const Eigen::MatrixXd& vectors = band.vectors;
    phi_ = vectors.leftCols(m_);
    // The eigenvalues as Rayleigh quotients of this K0 (the static correction's).
    blocks_.lambda.resize(m_);
    for (Eigen::Index i = 0; i < m_; ++i)
      blocks_.lambda(i) = phi_.col(i).dot(k0 * phi_.col(i)) / phi_.col(i).dot(m0_ * phi_.col(i));
    reduced_ = m_ < n_;
    if (!reduced_) return true;
    if (!quasi_.init(k0, m0_, phi_, blocks_.lambda, limit))
      return fail(error,
                  "a band-limited run (max_frequency_hz): the stiffness where it is linearized "
                  "has a mode of negative stiffness below the band's");
    quasi_.set_forcing_rate(2.0 * M_PI * highest_harmonic_hz(model));
    return true;
  }

  // The modes' damping c_i = phi_i^T M0 C phi_i (C = -da/du at the linearization, from central
  // differences of the accelerations in the velocity phi_i: the forces linear in the velocities
  // exactly, the gyroscopic ones, quadratic, cancelled) into blocks_.damping, integrated exactly
  // with each mode's block; the rest of C (its coupling between modes) stays in N. Its size,
  // |C phi_i - c_i phi_i| in M0's inverse (with every mode: the norm of the column of Phi^T M0 C
  // Phi off its diagonal), largest over the modes, into damping_coupling_. False when the
  // forces are not finite.
  bool modal_damping(double t0) {
    constexpr double kVelocity = 1e-3;  // the modal velocity of the differences
    blocks_.damping.setZero(m_);
    damping_coupling_ = 0.0;
    Block x(n_, 2);
    Eigen::VectorXd difference(n_);
    for (Eigen::Index i = 0; i < m_; ++i) {
      for (const double sign : {1.0, -1.0}) {
        x.col(0).setZero();
        x.col(1) = sign * kVelocity * phi_.col(i);
        if (!states_of(t0, x, y13_.data()) || !accelerations(t0, x)) return false;
        if (sign > 0.0)
          difference = acceleration_;
        else
          difference -= acceleration_;
      }
      const Eigen::VectorXd column = (-0.5 / kVelocity) * difference;  // C phi_i, M0^-1 applied
      const Eigen::VectorXd m0_column = m0_ * column;
      const double mass = phi_.col(i).dot(m0_ * phi_.col(i));  // 1 but for rounding
      double c = phi_.col(i).dot(m0_column) / mass;
      const double size2 = column.dot(m0_column) / mass;
      damping_coupling_ = std::max(damping_coupling_, std::sqrt(std::max(0.0, size2 - c * c)));
      // Negative (rounding, or a velocity force that feeds the motion): left in N. Near
      // critical damping the step's functions lose accuracy (exponential_step.hpp): the block
      // takes a damping off it, N the difference.
      blocks_.damping(i) = off_critical(blocks_.lambda(i), std::max(c, 0.0));
    }
    if (!(blocks_.damping.maxCoeff() > 0.0)) blocks_.damping.resize(0);
    return true;
  }

  // out = Psi^T v = Phi^T (M0 v), the modal part of the physical vector v (M0 is a 6 x 6 block
  // per body; Phi alone is stored and read, so that each stage's passes share one n x m matrix).
  void project(const Eigen::Ref<const Eigen::VectorXd>& v, double* out) {
    m0_v_.noalias() = m0_ * v;
    multiply_transposed(phi_, m0_v_.data(), out);
  }

  // One Newton correction of the quasi-static part: y += R M0 a, with Psi^T a given (psi_a);
  // returns its size in weights of the motion, rtol x + atol, x the largest offset from the
  // linearization (of the translations for theirs, of the rotations for theirs): the tolerance
  // a run's error is measured against (verify, work-precision studies). Not the step's weights,
  // rtol |c| + atol of the centres c: those depend on where the scene sits, and what is left of
  // y acts through the stiffness of the modes above the band. A 1 kg bob 0.3 m below a revolute
  // joint of relative compliance 1e-9, in a band of 20 Hz at rtol 1e-4, atol 1e-9, under a 1e-3
  // N m torque at 2 Hz for 1 s, came out 611 times rtol x + atol off its closed form with the
  // step's weights (3e-5 m across the swing: y stopped within 3e-10 m of a joint of 6e12 N/m),
  // and 0.04 times with the bob at the origin and the joint above it (tests/core/analysis/
  // transient_auto_test.cpp, TransientBand). What it costs: docs/transient_measurements.md "A
  // band's quasi-static part, wherever the scene sits". Weights of each offset, rtol |x_i| + atol,
  // are tighter still where an offset is small (along a chain's stiff axis) and took the
  // 1,000-segment cantilever 115 s (these 107 s, the step's weights 73 s) for the same error; these
  // weights with the iteration stopped at 1e-3 of them (kQuasiStaticTolerance) 84 s, but the bob 11
  // to 86 times off.
  double correct(const Eigen::VectorXd& psi_a, Block& x) {
    m0_a_.noalias() = m0_ * acceleration_;
    const Eigen::VectorXd& dy = quasi_.correct(m0_a_, psi_a);
    x.col(0) += dy;
    double largest[2] = {0.0, 0.0};  // translations, rotations
    for (Eigen::Index r = 0; r < n_; ++r) {
      double& l = largest[(r % kD) / 3];
      l = std::max(l, std::abs(x(r, 0)));
    }
    const double w[2] = {options_.rtol * largest[0] + options_.atol,
                         options_.rtol * largest[1] + options_.atol};
    double sum = 0.0;
    for (Eigen::Index r = 0; r < n_; ++r) {
      const double e = dy(r) / w[(r % kD) / 3];
      sum += e * e;
    }
    return std::sqrt(sum / static_cast<double>(n_));
  }

  // The quasi-static iteration's matrix from the tangent at the state of the last evaluation
  // (y13_): the rotation of stiff members with the motion makes K0 a poor Newton matrix for
  // the modes above the band (a stiff axial mode turned by the bending), and the iteration
  // slows or diverges. One sparse factorization and m solves.
  bool update_tangent() {
    const Model& model = context_->model;
    Data& data = context_->data;
    set_state(model, data, y13_.data());
    compute_wrenches(model, data, context_->force_time(t_));
    compute_tangent(model, data, context_->force_time(t_), false);
    ++stats_.jacobian_evaluations;
    return quasi_.update_tangent(-stiffness_matrix(model, data));
  }

  // z from the 13 states of every free body.
  void from_states(const double* y) {
    Block x;
    coordinates_.offsets(t_, y, x);
    z_.resize(m_, 2);
    project(x.col(0), z_.col(0).data());
    project(x.col(1), z_.col(1).data());
    multiply(phi_, z_, x_);
    if (reduced_) {
      // The part outside the band as a first guess of the quasi-static one.
      quasi_.y() = x.col(0) - x_.col(0);
      x_.col(0) += quasi_.y();
    }
  }

  // Physical coordinates x = Phi z into the 13 states; false (with far_body_ set) when a body
  // turned too far.
  bool states_of(double t, const Block& x, double* y) {
    return coordinates_.states(t, x, y, max_rotation_, &far_body_);
  }

  // The accepted state (a rotation past the limit is reported by the next step that uses it),
  // with the quasi-static part's rate in the velocities when known.
  void to_states(double* y) {
    if (!(reduced_ && quasi_.rate_known())) {
      coordinates_.states(t_, x_, y);
      return;
    }
    Block x = x_;
    x.col(1) += quasi_.rate();
    coordinates_.states(t_, x, y);
  }

  // The accelerations (dv/dt, d^2 theta/dt^2) into acceleration_ at the physical state x whose
  // 13 states states_of has just written into y13_; false when they are not finite.
  bool accelerations(double t, const Block& x) {
    state_derivative(context_->model, context_->data, context_->force_time(t), y13_.data(),
                     ydot13_.data());
    ++stats_.rhs_evaluations;
    return coordinates_.accelerations(x, ydot13_.data(), acceleration_);
  }

  // N(t, z) of a band-limited run: everything but the modes' linear part, in modal coordinates,
  // with the quasi-static part iterated into x (x = Phi z + y is given). Every mode integrated,
  // step() projects N in its passes instead. False when the forces are not finite or a body
  // turned too far.
  bool nonlinear(double t, const Block& z, Block& x, Block& out, int* flag) {
    out.resize(m_, 2);
    out.col(0).setZero();
    double last_size = 0.0;
    bool updated_here = false;
    for (int iteration = 0;; ++iteration) {
      if (!evaluate(t, x, flag)) return false;
      psi_a_.resize(m_);
      multiply_transposed(phi_, m0_v_.data(), psi_a_.data());  // Phi^T M0 a
      // Quasi-static outside the band: corrected until the correction is a small part of the
      // tolerance (the accelerations of the last evaluation are kept).
      const double size = correct(psi_a_, x);
      // A correction that grows, or shrinks slowly, beyond the tolerance: the Newton matrix
      // is updated to the tangent here, once per evaluation; if it then grows, the state is
      // too far out for the iteration (a trial step too long), which fails like non-finite
      // forces: the step is retried shorter. One that stops shrinking within the tolerance is
      // at its rounding floor. (Failing on a slow shrink after the update too failed the
      // cantilever of modal_band_test.cpp at rtol 1e-10 at a load's jump: 5.8 then 1.9 weights,
      // converging.) One still beyond the tolerance after kQuasiStaticIterations fails too.
      if (!std::isfinite(size) || (iteration >= kQuasiStaticIterations && size >= 1.0)) {
        *flag = kNonFinite;
        return false;
      }
      if (iteration > 0 && size > (updated_here ? 1.0 : 0.3) * last_size && size >= 1.0) {
        if (updated_here || !update_tangent()) {
          *flag = kNonFinite;
          return false;
        }
        updated_here = true;
      }
      if (size < kQuasiStaticTolerance || iteration >= kQuasiStaticIterations ||
          (iteration > 0 && size > 0.5 * last_size && size < 1.0)) {
        out.col(1) = psi_a_;
        break;
      }
      last_size = size;
    }
    out.col(1).array() += blocks_.lambda * z.col(0).array();
    if (blocks_.damped()) out.col(1).array() += blocks_.damping * z.col(1).array();
    return true;
  }

  // The accelerations at the physical state x and M0 a into m0_v_, for a projection that
  // finishes N (every mode integrated: N = Phi^T M0 a + lambda z, project_then). False when the
  // forces are not finite or a body turned too far.
  bool evaluate(double t, const Block& x, int* flag) {
    if (!states_of(t, x, y13_.data())) {
      *flag = kTooFar;
      return false;
    }
    if (!accelerations(t, x)) {
      *flag = kNonFinite;
      return false;
    }
    // An element outside its law's range (checked at every evaluation, as the right-hand side
    // of the other methods does, not only at the outputs: a carriage that left its rail's
    // travel and came back between two outputs was once followed on, ok and silent).
    if (context_->data.out_of_range) {
      char when[48];
      std::snprintf(when, sizeof when, "at t = %.9g s, ", t);
      context_->out_of_range = when + element_out_of_range(context_->model, context_->data);
      *flag = kOutOfRange;
      return false;
    }
    m0_v_.noalias() = m0_ * acceleration_;
    return true;
  }

  // One trial step of size f.h from the accepted state (t_, z_): the new state into next_, and
  // with its two error distances into trial_ (modal) and trial_x_ (physical). N(t_, z_) is n0_
  // when have_n0_; else its accelerations are in m0_v_ (evaluate). Every mode integrated, each
  // stage's forcing is projected in the pass over Phi that makes the next stage's physical state
  // (or the new state and its distances): multiply_transposed_then, one pass for two products
  // and the same bits. Band-limited, the quasi-static iteration projects it on its own.
  bool step(const StepFunctions& f, int* flag) {
    constexpr int s = StepFunctions::kStages;
    int pending = have_n0_ ? -1 : 0;  // the stage whose forcing awaits its projection
    if (have_n0_) stage_n_[0] = n0_;
    trial_.resize(m_, 6);
    trial_x_.resize(n_, 6);
    xi_.resize(n_, 2);
    for (int i = 1; i <= s; ++i) {  // i == s: the new state
      // What is known of stage i (or the new state) before the pending forcing, in the order of
      // the method's sums (the pending stage is the last one summed).
      Block& target = i < s ? stage_z_[i % 2] : next_;
      target.setZero(m_, 2);
      apply_add(i < s && StepFunctions::c[i] != 1.0 ? f.e_half : f.e_full, blocks_, z_, target);
      for (int j = 0; j < i; ++j) {
        const ModeFunction& weight = i < s ? f.a[i][j] : f.b[j];
        if (j != pending && !weight.empty()) apply_add(weight, blocks_, stage_n_[j], target, f.h);
      }
      if (pending >= 0) {
        project_then(f, i, i < s ? target.data() : trial_.data(), i < s ? 2 : 6,
                     i < s ? xi_.data() : trial_x_.data());
        if (pending == 0) {
          n0_ = stage_n_[0];
          have_n0_ = true;
        }
      } else if (i < s) {
        multiply(phi_, target, xi_);
      } else {
        estimates(f, 0, m_);
        multiply_three_pairs(phi_, trial_.data(), trial_x_.data());
      }
      if (i == s) break;
      const double t = t_ + StepFunctions::c[i] * f.h;
      if (reduced_) {
        xi_.col(0) += quasi_.y();
        if (!nonlinear(t, target, xi_, stage_n_[i], flag)) return false;
      } else {
        if (!evaluate(t, xi_, flag)) return false;
        pending = i;
      }
    }
    return true;
  }

  // The pass over Phi that projects stage `stage - 1`'s forcing (M0 a in m0_v_) and multiplies
  // x (m x vectors, written on the way by fill with the step's functions f) into y.
  void project_then(const StepFunctions& f, int stage, double* x, int vectors, double* y) {
    fill_functions_ = &f;
    fill_stage_ = stage;
    Block& n = stage_n_[stage - 1];
    n.resize(m_, 2);
    n.col(0).setZero();
    multiply_transposed_then(phi_, m0_v_.data(), n.col(1).data(), fill_rows, this, vectors, x, y);
  }

  static void fill_rows(void* self, long begin, long end) {
    static_cast<ModalExponential*>(self)->fill(begin, end - begin);
  }

  // The `count` modes from `begin` of the projected stage's N (Phi^T M0 a, written by the pass,
  // + lambda z), then of what the pass multiplies: stage fill_stage_'s state, or at the step's
  // end the new state and its distances.
  void fill(Eigen::Index begin, Eigen::Index count) {
    constexpr int s = StepFunctions::kStages;
    const StepFunctions& f = *fill_functions_;
    const int j = fill_stage_ - 1;
    Block& n = stage_n_[j];
    const Block& zj = j == 0 ? z_ : stage_z_[j % 2];
    n.col(1).segment(begin, count).array() +=
        blocks_.lambda.segment(begin, count) * zj.col(0).segment(begin, count).array();
    if (blocks_.damped())
      n.col(1).segment(begin, count).array() +=
          blocks_.damping.segment(begin, count) * zj.col(1).segment(begin, count).array();
    const ModeFunction& weight = fill_stage_ < s ? f.a[fill_stage_][j] : f.b[j];
    Block& target = fill_stage_ < s ? stage_z_[fill_stage_ % 2] : next_;
    if (!weight.empty()) apply_add(weight, blocks_, n, target, f.h, begin, count);
    if (fill_stage_ == s) estimates(f, begin, count);
  }

  // The `count` modes from `begin` of the new state's two error distances (next_ holds the new
  // state), and the three side by side into trial_: the distance to the embedded third-order
  // solution, h b5 (N5 - N3), and to the embedded second-order one from stages 1 and 2.
  void estimates(const StepFunctions& f, Eigen::Index begin, Eigen::Index count) {
    third_.resize(m_, 2);
    third_.middleRows(begin, count).setZero();
    apply_add(f.b[4], blocks_, stage_n_[4], third_, f.h, begin, count);
    apply_add(f.b[4], blocks_, stage_n_[2], third_, -f.h, begin, count);
    second_.resize(m_, 2);
    second_.middleRows(begin, count) = next_.middleRows(begin, count);
    apply_add(f.e_full, blocks_, z_, second_, -1.0, begin, count);
    apply_add(f.low[0], blocks_, stage_n_[0], second_, -f.h, begin, count);
    apply_add(f.low[1], blocks_, stage_n_[1], second_, -f.h, begin, count);
    trial_.block(begin, 0, count, 2) = next_.middleRows(begin, count);
    trial_.block(begin, 2, count, 2) = third_.middleRows(begin, count);
    trial_.block(begin, 4, count, 2) = second_.middleRows(begin, count);
  }

  // Weighted RMS norm of an error e = Phi dz in the physical states (x: rtol |c| + atol for
  // positions, rtol + atol for rotations; u: rtol |u| + atol) at the physical state x.
  double error_norm(const Eigen::Ref<const Block>& e, const Block& x) {
    double sum = 0.0;
    for (int b = 0; b < coordinates_.bodies(); ++b)
      for (int j = 0; j < kD; ++j) {
        const Eigen::Index r = kD * static_cast<Eigen::Index>(b) + j;
        const double wx = coordinates_.offset_weight(b, j, x, options_.rtol, options_.atol);
        const double wu = options_.rtol * std::abs(x(r, 1)) + options_.atol;
        sum += (e(r, 0) / wx) * (e(r, 0) / wx) + (e(r, 1) / wu) * (e(r, 1) / wu);
      }
    return std::sqrt(sum / (2.0 * static_cast<double>(n_)));
  }

  // The error estimate: the distance to the embedded third-order solution, O(h^4), over
  // kToleranceScale, and the distance to the embedded second-order one, O(h^3), over
  // kLowOrderScale rtol^(3/4): both ask for steps ~ rtol^(1/4), so the achieved error of the
  // fourth-order solution kept follows rtol. The third-order estimate alone compares two
  // evaluations at the same time (c = 1/2) and misses forcing that varies fast within a step: a
  // step torque that sets a 6-segment cantilever's torsion (5.6e5 rad/s) beating against its
  // bending gave 6 .. 290 rtol with it alone (the previous engineer's note, not re-measured); the
  // second-order one sees that. Measured against tight explicit runs over rtol 1e-4 .. 1e-9
  // (transient_auto_test.cpp, ErrorFollowsTheTolerance, auto): 0.011 .. 0.060 rtol on the
  // reference cantilever in 10 segments, 0.017 .. 1.3 on that torsion case, 0.13 .. 1.9 on the
  // tumbling pair (relinearized, in fixed axes: since followed in a turning frame, 0.02 .. 0.13);
  // the second-order estimate alone gave 1e-2 .. 1e-5 rtol there.
  // Where it costs: the braced tower of docs/transient_measurements.md (1,038 dof, 2 kN step,
  // rtol 1e-6, atol 1e-9, 0.2 s) takes 797 steps held by the second-order estimate, almost all of
  // it in the angular velocities (atol-weighted: they are near zero), and leaves 0.03 rtol. The
  // forcing there is the deflection times the fast modes (its steps follow the band's top: 246,
  // 613, 786 and 797 steps for bands of 300 Hz, 1 kHz, 3 kHz and every mode). Tried and rejected,
  // measured with ErrorFollowsTheTolerance: the second-order estimate at 0.1 of its weight (tower
  // 298 steps, 0.4 rtol) leaves 20 rtol on the step-torque case at rtol 1e-5; on positions only, or
  // the third-order one alone (185 steps, 2.6 rtol), 16 .. 476 rtol there; from stages 1 and 4
  // (exponential trapezoid) instead of 1 and 2, 741 steps; weights rtol |omega| + atol per body:
  // 445 steps, 14 .. 99 rtol there (small bending rates beside the torsion set the deflection).
  static constexpr double kExponent = 0.25;
  // The quasi-static iteration stops when its correction is below this part of the error
  // weights: what is left of it enters the forcing through the stiffness of the modes above the
  // band, and the step control sees it as error. Measured on the reference cantilever in 10
  // segments, rtol 1e-7, 0.1 s (TransientBand): at 0.05, bands 500 and 2000 Hz took 1,630 and
  // 2,596 steps (the full model 1,407); at 1e-2, 126 and 2,598; at 1e-3, 100 (one per output)
  // and 437, with 1,071 and 4,825 evaluations; at 1e-5, 100 and 441 with 1,369 and 6,580. On a
  // bending chain the rest of the iteration is what holds the steps: the 1,000-segment cantilever
  // under 1 N over 60 ms took 4,106 steps and 20,966 evaluations at 1e-3, 1,916 and 13,718 at
  // 1e-5, 1,348 and 18,180 at 1e-7 (1,349 and 27,525 at 1e-9); the 201-segment one over 10 ms
  // left 3.0 and 2.9 rtol at 1e-3 against an independent run, 0.54 and 0.71 rtol at 1e-5 (rtol
  // 1e-4, 1e-5; tests/core/analysis/transient_auto_test.cpp). (Those were measured in the step's
  // weights; the iteration now stops in the motion's, correct().)
  static constexpr double kQuasiStaticTolerance = 1e-5;
  // The corrections of one evaluation of the band's forcing at most.
  static constexpr int kQuasiStaticIterations = 8;
  // A floating part is followed in a turning frame when it turns more than this over the run
  // [rad].
  static constexpr double kTurningFrameMinTurn = 1e-3;
  static constexpr double kToleranceScale = 10.0;
  static constexpr double kLowOrderScale = 3.0;

  // Advances by one accepted step (or to `target`). Returns a flag.
  int step_towards(double target) {
    if (context_->should_stop()) return kTooManySteps;
    if (stats_.steps >= options_.max_steps) return kTooManySteps;
    int flag = kOk;
    try {
      if (!have_n0_) {
        // Band-limited, N at the accepted state now; else its accelerations, projected in the
        // step's first pass.
        if (reduced_ ? !nonlinear(t_, z_, x_, n0_, &flag) : !evaluate(t_, x_, &flag))
          return fail_flag(flag);
        have_n0_ = reduced_;
      }
      if (reduced_) quasi_.begin_step();  // the quasi-static part at the accepted state
      if (h_ <= 0.0) h_ = options_.initial_step > 0.0 ? options_.initial_step : (target - t_);
      // A mechanism's first step (from the run's start, a load's jump or auto's relinearization):
      // the modes as they will ring about the static state of the forces there.
      const ModeBlock& ringing = starting_ && bounds_.mechanism_wh > 0.0 ? start_ringing() : z_;
      // No element carried across an edge of its range or of its warnings unseen (edge_step:
      // the modes that could reach it resolved, the rigid and slow modes' paths bounded;
      // data.pose is the accepted state's, just evaluated), a mechanism's too (its ringing modes
      // also have their own bounds).
      double longest = std::min(h_, target - t_);
      if (options_.max_step > 0.0) longest = std::min(longest, options_.max_step);
      const double edge_h = edge_step(longest);
      for (int attempt = 0;; ++attempt) {
        double h = std::min(h_, target - t_);
        if (options_.max_step > 0.0) h = std::min(h, options_.max_step);
        const bool mechanism_holds = mechanism_bound(ringing);
        const double asked = h;
        h = bounds_.limit(h, h_, mechanism_holds, mechanism_holds ? 0.0 : ringing_rate(ringing));
        const bool held = h < kMechanismHeldShare * asked;
        h = std::min(h, edge_h);
        // Land on the target instead of leaving a sliver.
        if (t_ + 1.05 * h >= target) h = target - t_;
        if (!(h > 1e-14 * std::max(1.0, std::abs(t_))))
          return context_->out_of_range.empty() ? kStepTooSmall : kOutOfRange;
        // The step's functions depend on h alone (the blocks are set at init): a step as long
        // as the last (a mechanism's bound, max_step) reuses them.
        if (h != full_.h) full_.compute(h, blocks_);
        if (reduced_) quasi_.restore();  // not a rejected trial's
        int sflag = kOk;
        const bool ok = step(full_, &sflag);
        double err = 0.0;
        if (ok) {
          // The distances to the embedded third-order solution and to the embedded second-order
          // one against rtol^(3/4) (both then ask for steps ~ rtol^(1/4)), as physical states.
          x_next_ = trial_x_.leftCols<2>();
          err = std::max(error_norm(trial_x_.middleCols<2>(2), x_next_) / kToleranceScale,
                         error_norm(trial_x_.rightCols<2>(), x_next_) * low_order_weight_);
          if (!std::isfinite(err)) err = 1e10;
        } else if (sflag == kNonFinite) {
          // Perhaps a trial state too far out: retry smaller before giving up.
          if (attempt >= 10) return fail_flag(sflag);
          err = 1e10;
        } else if (sflag == kOutOfRange) {
          // A trial state outside an element's range: shorter, until the run stops where the
          // element leaves it (a trial step too long may also overshoot and come back).
          if (++context_->nonfinite_evaluations >= kNonFiniteLimit) return kOutOfRange;
          ++stats_.error_test_failures;
          h_ = 0.5 * h;
          continue;
        } else if (sflag == kTooFar && attempt < 10 && largest_rotation() < 0.5 * max_rotation_) {
          // A trial step that overshoots the rotation limit from well inside it: shorter, so that
          // the run stops (or auto relinearizes) near the limit, not a long step before it.
          ++stats_.error_test_failures;
          h_ = 0.5 * h;
          continue;
        } else {
          return fail_flag(sflag);
        }
        if (err <= 1.0) {
          t_ = (h == target - t_) ? target : t_ + h;
          z_.swap(next_);
          x_.swap(x_next_);
          if (reduced_) {
            x_.col(0) += quasi_.y();
            quasi_.accepted(h, StepFunctions::c[StepFunctions::kStages - 1], z_.col(1));
          }
          have_n0_ = false;
          starting_ = false;
          ++stats_.steps;
          ++held_.steps;
          if (held)
            ++held_.held;
          else if (static_cast<double>(held_.held) < kMechanismHeldStretch * held_.steps)
            held_ = {};
          if (context_->step_taken) {  // every step that uses it writes its own states again
            coordinates_.states(t_, x_, watched_.data());
            context_->path_bounded = true;
            context_->step_taken(t_, watched_.data());
            context_->path_bounded = false;
            // An element outside its law's range on the path between two steps (transient.cpp).
            if (!context_->divergence.empty()) return kOutOfRange;
          }
          const double grow = err > 0.0 ? 0.9 * std::pow(err, -kExponent) : 4.0;
          if (h >= 0.999 * h_ || grow < 1.0) h_ = h * std::clamp(grow, 0.2, attempt ? 1.0 : 4.0);
          return kOk;
        }
        ++stats_.error_test_failures;
        h_ = h * std::clamp(0.9 * std::pow(err, -kExponent), 0.1, 0.5);
      }
    } catch (const std::exception& e) {
      context_->callback_error = e.what();
      return kNonFinite;
    }
  }

 public:
  QuasiStaticInertia quasi_static_inertia() const { return quasi_.inertia(band_hz_, t_, t_ - t0_); }

  // advance() stops (kInertia) after the step whose drift first passes `drift` (0: never), once
  // inertia_settled().
  void set_inertia_limit(double drift) { inertia_limit_ = drift; }

  // advance() stops (kHeld) after the step at which the held steps of the latest stretch reach
  // `held` (0: never).
  void set_held_limit(long held) { held_limit_ = held; }
  void continue_held_steps(const HeldSteps& stretch) { held_ = stretch; }

  // Whether the band's slowest elastic mode has turned kInertiaSettling rad since the run began.
  // Before, a load that starts from rest gives a ratio of kinetic energies far above the
  // motion's: the quasi-static part follows the load at once, the band only over about a third
  // of its period (the heavy tip's smooth ramp: 9e-5 at 5 ms, 1e-7 at 2 rad, 5e-8 from then on).
  bool inertia_settled() const { return quasi_.settled(t_ - t0_, kInertiaSettling); }

  bool band_limited() const { return reduced_; }

  std::vector<std::string> closing_warnings() const override {
    if (!reduced_) return {};
    const QuasiStaticInertia q = quasi_static_inertia();
    if (!(q.drift > options_.rtol)) return {};
    return {quasi_static_inertia_warning(q)};
  }

 private:
  int fail_flag(int flag) {
    if (flag == kTooFar && far_body_ >= 0) {
      const Model& model = context_->model;
      detail_ = "body \"" + model.bodies[model.free_bodies[far_body_]].name +
                "\" turned more than " + rotation_limit_text() +
                " from the orientation it is linearized about" + turning_text(far_body_) +
                ": the modal integrator is for small motions about one configuration; use bdf "
                "or dirk";
    }
    return flag;
  }

  // " (turning with its part of the scene at W rad/s)" for a body in a turning frame, else "".
  std::string turning_text(int body) const {
    const double rate = coordinates_.frame_rate(body);
    if (!(rate > 0.0)) return "";
    char text[80];
    std::snprintf(text, sizeof text, " (turning with its part of the scene at %.3g rad/s)", rate);
    return text;
  }

 public:
  // The angular velocity of the frame the run follows the scene in [rad/s]; 0 in fixed axes.
  double frame_rate() const { return coordinates_.fastest_frame_rate(); }

 private:
  IntegratorOptions options_;
  OdeContext* context_ = nullptr;
  Eigen::Index n_ = 0;  // degrees of freedom
  Eigen::Index m_ = 0;  // modes integrated (n_ unless band-limited)
  // Band-limited (m_ < n_): the modes above the band are quasi-static, x = Phi z + y
  // (core/analysis/quasi_static_modes.hpp).
  bool reduced_ = false;
  QuasiStaticModes quasi_;
  Eigen::SparseMatrix<double> m0_;
  Eigen::VectorXd m0_a_, psi_a_;  // work space: M0 a, Phi^T M0 a
  Eigen::ArrayXd edge_psi_a_;     // work space of edge_step: Phi^T M0 a at the accepted state
  Block n0_;                      // N at the accepted state, when have_n0_
  bool have_n0_ = false;
  bool starting_ = true;          // no step accepted since the start or the last restart
  ModeBlock start_ringing_;       // start_ringing()
  double band_hz_ = 0.0;          // the highest frequency integrated [Hz]
  double band_estimate_ = -1.0;   // a chosen band's estimated error (modal_band.hpp); -1: given
  InitialLinearization initial_;  // why the initial state was linearized about (modal_reference)
  Eigen::Index band_needed_ = 0;  // the modes the chosen band needed
  Eigen::MatrixXd phi_;           // x = Phi z, z = Psi^T x with Psi = M0 Phi (project)
  ElementReach reach_;            // how far each mode moves each element, in xi and angle
  Eigen::VectorXd m0_v_;          // work space of project
  ModeBlocks blocks_;  // the modes' linear part: eigenvalues and damping (exponential_step.hpp)
  double damping_coupling_ = 0.0;  // modal_damping: the damping left in N, per mode velocity
  ModalCoordinates coordinates_;   // the bodies' offsets from the linearization and back
  Block z_, x_;                    // the accepted state, modal and physical (x_ = Phi z_)
  Block xi_, x_next_;              // work space: a stage's physical state, a trial step's
  // A trial step's new state and its two error estimates side by side, modal and physical.
  Eigen::Matrix<double, Eigen::Dynamic, 6> trial_, trial_x_;
  // Work space: the modal states of the last two stages, a trial step's new state, its distances.
  Block stage_z_[2], next_, third_, second_;
  int fill_stage_ = 0;  // the stage (kStages: the new state) whose pass is under way, and
  const StepFunctions* fill_functions_ = nullptr;  // the functions of its step
  double inertia_limit_ = 0.0;                     // set_inertia_limit
  long held_limit_ = 0;                            // set_held_limit
  Eigen::VectorXd acceleration_;  // work space: the physical accelerations of a stage
  double t_ = 0.0, h_ = 0.0;
  double t0_ = 0.0;  // where the run started
  StepFunctions full_;
  Block stage_n_[StepFunctions::kStages];
  std::vector<double> y13_, ydot13_;
  std::vector<double> watched_;  // an accepted step's states, for OdeContext::step_taken
  SolverStats stats_;
  HeldSteps
      held_;  // the latest stretch of steps the mechanism's bounds held (kMechanismHeldStretch)
  int far_body_ = -1;
  std::string detail_;
  double max_rotation_ = kModalIntegratorMaxRotation;
  std::vector<Eigen::Index> order_;  // the modes from the fastest down
  ModalStepBounds bounds_;         // the longest steps beside the estimates (modal_step_bounds.hpp)
  double low_order_weight_ = 1.0;  // rtol^(1/4) / kLowOrderScale
};

}  // namespace

double modal_frame_rate(const Integrator& integrator) {
  const auto* modal = dynamic_cast<const ModalExponential*>(&integrator);
  return modal ? modal->frame_rate() : 0.0;
}

bool modal_spectrum(const Integrator& integrator, double* smallest_positive, double* largest) {
  const auto* modal = dynamic_cast<const ModalExponential*>(&integrator);
  if (!modal) return false;
  const Eigen::ArrayXd& lambda = modal->eigenvalues();
  *largest = lambda.size() ? lambda.maxCoeff() : 0.0;
  *smallest_positive = 0.0;
  // Rigid modes have w^2 near 0 (rounding): positive means above 1e-12 of the largest.
  for (Eigen::Index i = 0; i < lambda.size(); ++i)
    if (lambda(i) > 1e-12 * *largest &&
        (*smallest_positive == 0.0 || lambda(i) < *smallest_positive))
      *smallest_positive = lambda(i);
  return true;
}

bool modal_damping(const Integrator& integrator, double* largest, double* coupling) {
  const auto* modal = dynamic_cast<const ModalExponential*>(&integrator);
  if (!modal) return false;
  *largest = modal->damping().size() ? modal->damping().maxCoeff() : 0.0;
  *coupling = modal->damping_coupling();
  return true;
}

InitialLinearization modal_initial_linearization(const Integrator& integrator) {
  const auto* modal = dynamic_cast<const ModalExponential*>(&integrator);
  return modal ? modal->initial_linearization() : InitialLinearization{};
}

std::string modal_band_choice(const Integrator& integrator) {
  const auto* modal = dynamic_cast<const ModalExponential*>(&integrator);
  return modal ? modal->band_choice() : "";
}

bool modal_quasi_static_inertia(const Integrator& integrator, QuasiStaticInertia* out) {
  const auto* modal = dynamic_cast<const ModalExponential*>(&integrator);
  if (!modal || !modal->band_limited()) return false;
  *out = modal->quasi_static_inertia();
  return true;
}

std::string quasi_static_inertia_warning(const QuasiStaticInertia& q) {
  char text[700];
  std::snprintf(text, sizeof text,
                "band-limited run (%.4g Hz): the modes above the band, which it keeps "
                "quasi-static, moved with up to %.2g of the band's kinetic energy (motion they "
                "follow at second order, such as a heavy body pulled along by a bending beam); "
                "the run leaves that energy out, so its frequencies are off by about that much "
                "and its error is estimated at %.2g of the motion by t = %.6g s, above rtol: "
                "integrate more modes (a higher max_frequency_hz) or every mode",
                q.band_hz, q.ratio, q.drift, q.t);
  return text;
}

bool set_modal_inertia_limit(Integrator& integrator, double drift) {
  auto* modal = dynamic_cast<ModalExponential*>(&integrator);
  if (!modal || !modal->band_limited()) return false;
  modal->set_inertia_limit(drift);
  return true;
}

bool set_modal_held_limit(Integrator& integrator, long held) {
  auto* modal = dynamic_cast<ModalExponential*>(&integrator);
  if (!modal) return false;
  modal->set_held_limit(held);
  return true;
}

void continue_modal_held_steps(const Integrator& from, Integrator& to) {
  const auto* previous = dynamic_cast<const ModalExponential*>(&from);
  auto* next = dynamic_cast<ModalExponential*>(&to);
  if (previous && next) next->continue_held_steps(previous->held_steps());
}

bool modal_mechanism_bound(const Integrator& integrator) {
  const auto* modal = dynamic_cast<const ModalExponential*>(&integrator);
  return modal && modal->mechanism_bound();
}

void hold_modal_mechanism_bound(Integrator& integrator) {
  if (auto* modal = dynamic_cast<ModalExponential*>(&integrator)) modal->hold_mechanism_bound();
}

double modal_step_size(const Integrator& integrator) {
  const auto* modal = dynamic_cast<const ModalExponential*>(&integrator);
  return modal ? modal->step_size() : 0.0;
}

HeldSteps modal_held_steps(const Integrator& integrator) {
  const auto* modal = dynamic_cast<const ModalExponential*>(&integrator);
  return modal ? modal->held_steps() : HeldSteps{};
}

std::unique_ptr<Integrator> make_modal_integrator(const IntegratorOptions& options,
                                                  OdeContext& context, N_Vector y0,
                                                  std::string* error, double t0) {
  auto integrator = std::make_unique<ModalExponential>();
  if (!integrator->init(options, context, y0, error, t0)) return nullptr;
  return integrator;
}

}  // namespace beamrail
