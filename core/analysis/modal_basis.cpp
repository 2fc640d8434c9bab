// The modal integrator's set-up (core/analysis/modal_exponential.hpp): the linearization, its
// modes (every mode, or a band and the static correction of the modes above it) and their damping.
#include "core/analysis/modal_exponential.hpp"

namespace beamrail::modal_detail {

bool ModalExponential::init(const IntegratorOptions& o, OdeContext& c, N_Vector y0,
                            std::string* error, double t0) {
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
  std::sort(order_.begin(), order_.end(),
            [&](Eigen::Index a, Eigen::Index b) { return blocks_.lambda[a] > blocks_.lambda[b]; });
  // How far each mode moves the elements per unit of its coordinate, in length and angle.
  {
    Data at_reference(model);
    set_state(model, at_reference, reference.data());
    reach_ = element_reach(model, at_reference, phi_);
  }
  bounds_ = ModalStepBounds(
      o.rtol, blocks_.lambda.size() > 0 ? std::sqrt(std::max(blocks_.lambda.maxCoeff(), 0.0)) : 0.0,
      coordinates_.turning(), moves_as_mechanism(model), highest_harmonic_hz(model));
  from_states(y);
  linear_solver = "modal";
  band_hz = m_ < n_ ? band_hz_ : 0.0;
  stats_.jacobian_evaluations = 1;  // the tangent of the linearization
  return true;
}

std::string ModalExponential::band_choice() const {
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

bool ModalExponential::band_limited_basis(const Model& model, Data& data, double t0,
                                          const double* y0, std::string* error) {
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
      std::chrono::duration<double>(context_->deadline - std::chrono::steady_clock::now()).count();
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

bool ModalExponential::modal_damping(double t0) {
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

}  // namespace beamrail::modal_detail
