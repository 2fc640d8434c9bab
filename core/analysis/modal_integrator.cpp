// The modal integrator's steps (core/analysis/modal_exponential.hpp; set up in
// core/analysis/modal_basis.cpp; the band's quasi-static part in
// core/analysis/modal_quasi_static.cpp) and its interface (core/analysis/modal_integrator.hpp).
#include "core/analysis/modal_exponential.hpp"

namespace beamrail {
namespace modal_detail {

int ModalExponential::advance(double tout, double tstop, N_Vector y, double* t) {
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
      if (!nonlinear_at_accepted(&flag)) flag = fail_flag(flag);
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

void ModalExponential::restart(double t, N_Vector y) {
  t_ = t;
  have_n0_ = false;
  starting_ = true;
  quasi_.restart();
  from_states(N_VGetArrayPointer(y));
}

const ModeBlock& ModalExponential::start_ringing() {
  if (!reduced_) {
    psi_a_.resize(m_);
    multiply_transposed(phi_, m0_v_.data(), psi_a_.data());
  }
  start_ringing_ = ringing_about_static_state(blocks_.lambda, z_, psi_a_);
  return start_ringing_;
}

double ModalExponential::edge_step(double h) {
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

std::string ModalExponential::failure(int flag) const {
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

void ModalExponential::from_states(const double* y) {
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

void ModalExponential::to_states(double* y) {
  if (!(reduced_ && quasi_.rate_known())) {
    coordinates_.states(t_, x_, y);
    return;
  }
  Block x = x_;
  x.col(1) += quasi_.rate();
  coordinates_.states(t_, x, y);
}

bool ModalExponential::accelerations(double t, const Block& x) {
  state_derivative(context_->model, context_->data, context_->force_time(t), y13_.data(),
                   ydot13_.data());
  ++stats_.rhs_evaluations;
  return coordinates_.accelerations(x, ydot13_.data(), acceleration_);
}

bool ModalExponential::evaluate(double t, const Block& x, int* flag) {
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

bool ModalExponential::step(const StepFunctions& f, int* flag) {
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

void ModalExponential::project_then(const StepFunctions& f, int stage, double* x, int vectors,
                                    double* y) {
  fill_functions_ = &f;
  fill_stage_ = stage;
  Block& n = stage_n_[stage - 1];
  n.resize(m_, 2);
  n.col(0).setZero();
  multiply_transposed_then(phi_, m0_v_.data(), n.col(1).data(), fill_rows, this, vectors, x, y);
}

void ModalExponential::fill(Eigen::Index begin, Eigen::Index count) {
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

void ModalExponential::estimates(const StepFunctions& f, Eigen::Index begin, Eigen::Index count) {
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

double ModalExponential::error_norm(const Eigen::Ref<const Block>& e, const Block& x) {
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

int ModalExponential::step_towards(double target) {
  if (context_->should_stop()) return kTooManySteps;
  if (stats_.steps >= options_.max_steps) return kTooManySteps;
  int flag = kOk;
  try {
    if (!have_n0_) {
      // Band-limited, N at the accepted state now; else its accelerations, projected in the
      // step's first pass.
      if (reduced_ ? !nonlinear_at_accepted(&flag) : !evaluate(t_, x_, &flag))
        return fail_flag(flag);
      have_n0_ = reduced_;
      if (reduced_ && stats_.steps == 0 && pull_ < 0.0) {
        pull_ = 0.0;
        if (!measure_pull(&flag)) return fail_flag(flag);
        // Already past what the run may drop: it stops before its first step (auto widens).
        if (inertia_limit_ > 0.0 && quasi_static_inertia().drift > inertia_limit_) return kInertia;
      }
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
          quasi_.accepted(h, StepFunctions::c[StepFunctions::kStages - 1], z_.col(1),
                          quasi_step_resolved());
          qs_noise_ = 0.0;
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

std::vector<std::string> ModalExponential::closing_warnings() const {
  if (!reduced_) return {};
  const QuasiStaticInertia q = quasi_static_inertia();
  if (!(q.drift > options_.rtol)) return {};
  return {quasi_static_inertia_warning(q)};
}

int ModalExponential::fail_flag(int flag) {
  if (flag == kTooFar && far_body_ >= 0) {
    const Model& model = context_->model;
    detail_ = "body \"" + model.bodies[model.free_bodies[far_body_]].name + "\" turned more than " +
              rotation_limit_text() + " from the orientation it is linearized about" +
              turning_text(far_body_) +
              ": the modal integrator is for small motions about one configuration; use bdf "
              "or dirk";
  }
  return flag;
}

std::string ModalExponential::turning_text(int body) const {
  const double rate = coordinates_.frame_rate(body);
  if (!(rate > 0.0)) return "";
  char text[80];
  std::snprintf(text, sizeof text, " (turning with its part of the scene at %.3g rad/s)", rate);
  return text;
}

}  // namespace modal_detail

using modal_detail::ModalExponential;

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

bool set_modal_settling_start(Integrator& integrator, double t) {
  auto* modal = dynamic_cast<ModalExponential*>(&integrator);
  if (!modal || !modal->band_limited()) return false;
  modal->set_settling_start(t);
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
