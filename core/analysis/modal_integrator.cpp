#include "core/analysis/modal_integrator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>

#include "core/analysis/dense_product.hpp"
#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/static_analysis.hpp"
#include "core/model/dynamics.hpp"
#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"
#include "core/model/rotation.hpp"

namespace beamrail {

namespace {

// The Taylor coefficients (-1)^j / (2j + m)! of g_m, j = 0..kTerms-1: at |x| < 4 the next term
// is below 1e-22 of the first.
constexpr int kTerms = 13;
template <int m>
constexpr std::array<double, kTerms> oscillator_coefficients() {
  std::array<double, kTerms> c{};
  double f = 1.0;  // (2j + m)!
  for (int i = 2; i <= m; ++i) f *= i;
  for (int j = 0; j < kTerms; ++j) {
    c[j] = (j % 2 ? -1.0 : 1.0) / f;
    f *= (2.0 * j + m + 1) * (2.0 * j + m + 2);
  }
  return c;
}

template <int m>
double oscillator_series(double x) {
  static constexpr std::array<double, kTerms> c = oscillator_coefficients<m>();
  double sum = c[kTerms - 1];
  for (int j = kTerms - 2; j >= 0; --j) sum = sum * x + c[j];
  return sum;
}

}  // namespace

std::array<double, 5> oscillator_g(double x) {
  std::array<double, 5> g{};
  if (std::abs(x) < 4.0) {
    // Series for g3 and g4, then g_m = 1/m! - x g_{m+2} down to g0 (for 0 < x < 4 the subtraction
    // loses at most a factor 3, at g0 = cos 2).
    g[4] = oscillator_series<4>(x);
    g[3] = oscillator_series<3>(x);
    g[2] = 0.5 - x * g[4];
    g[1] = 1.0 - x * g[3];
    g[0] = 1.0 - x * g[2];
    return g;
  }
  const double s = std::sqrt(std::abs(x));
  g[0] = x > 0 ? std::cos(s) : std::cosh(s);
  g[1] = x > 0 ? std::sin(s) / s : std::sinh(s) / s;
  // g_m = 1/m! - x g_{m+2}; at |x| >= 4 the subtraction loses at most a factor 3.
  const double inv_fact[3] = {1.0, 1.0, 0.5};
  for (int m = 0; m < 3; ++m) g[m + 2] = (inv_fact[m] - g[m]) / x;
  return g;
}

namespace {

constexpr int kD = kDofsPerBody;
constexpr int kS = kStatesPerBody;

using Block = Eigen::Matrix<double, Eigen::Dynamic, 2>;  // per mode: (eta, nu) or (x, u) columns

// out = a b (a change of basis of both columns).
void multiply(const Eigen::MatrixXd& a, const Block& b, Block& out) {
  out.resize(a.rows(), 2);
  multiply_pair(a, b.data(), out.data());
}

// A function of the mode blocks B_i = [[0, 1], [-lambda_i, 0]], f(B_i) = alpha_i I + beta_i B_i.
struct ModeFunction {
  Eigen::ArrayXd alpha, beta;
  ModeFunction() = default;
  explicit ModeFunction(Eigen::Index n) : alpha(Eigen::ArrayXd::Zero(n)), beta(alpha) {}
  bool empty() const { return alpha.size() == 0; }  // a zero coefficient: skipped
  ModeFunction& add(double s, const ModeFunction& f) {
    alpha += s * f.alpha;
    beta += s * f.beta;
    return *this;
  }
};

ModeFunction combine(std::initializer_list<std::pair<double, const ModeFunction*>> terms) {
  ModeFunction r(terms.begin()->second->alpha.size());
  for (const auto& [s, f] : terms) r.add(s, *f);
  return r;
}

// out += f(B) z, per mode.
void apply_add(const ModeFunction& f, const Eigen::ArrayXd& lambda, const Block& z, Block& out) {
  const auto a = z.col(0).array(), b = z.col(1).array();
  out.col(0).array() += f.alpha * a + f.beta * b;
  out.col(1).array() += f.alpha * b - f.beta * lambda * a;
}

// The coefficient functions of one step of size h of the stiff-order-4 exponential Runge-Kutta
// method (5 stages, c = 0, 1/2, 1/2, 1, 1/2):
//   Z_i = E(c_i h) z + h sum_j a_ij N_j,   z+ = E(h) z + h sum_j b_j N_j.
struct StepFunctions {
  static constexpr int kStages = 5;
  static constexpr double c[kStages] = {0.0, 0.5, 0.5, 1.0, 0.5};
  double h = 0.0;
  ModeFunction e_half, e_full;
  ModeFunction a[kStages][kStages];
  ModeFunction b[kStages];
  ModeFunction low[2];  // the embedded order-2 method: b1 = phi1 - 2 phi2, b2 = 2 phi2

  void compute(double step, const Eigen::ArrayXd& lambda) {
    h = step;
    const Eigen::Index n = lambda.size();
    ModeFunction phi_h[4], phi_f[4];  // phi_k(h/2 B), phi_k(h B)
    for (auto& f : phi_h) f = ModeFunction(n);
    for (auto& f : phi_f) f = ModeFunction(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      for (int half = 0; half < 2; ++half) {
        const double tau = half ? 0.5 * h : h;
        const std::array<double, 5> g = oscillator_g(lambda(i) * tau * tau);
        ModeFunction* phi = half ? phi_h : phi_f;
        for (int k = 0; k < 4; ++k) {
          phi[k].alpha(i) = g[k];
          phi[k].beta(i) = tau * g[k + 1];
        }
      }
    }
    e_half = phi_h[0];
    e_full = phi_f[0];
    for (auto& row : a)
      for (auto& f : row) f = ModeFunction();
    a[1][0] = combine({{0.5, &phi_h[1]}});
    a[2][0] = combine({{0.5, &phi_h[1]}, {-1.0, &phi_h[2]}});
    a[2][1] = phi_h[2];
    a[3][0] = combine({{1.0, &phi_f[1]}, {-2.0, &phi_f[2]}});
    a[3][1] = phi_f[2];
    a[3][2] = phi_f[2];
    a[4][1] = combine({{0.5, &phi_h[2]}, {-1.0, &phi_f[3]}, {0.25, &phi_f[2]}, {-0.5, &phi_h[3]}});
    a[4][2] = a[4][1];
    a[4][3] = combine({{0.25, &phi_h[2]}, {-1.0, &a[4][1]}});
    a[4][0] = combine({{0.5, &phi_h[1]}, {-2.0, &a[4][1]}, {-1.0, &a[4][3]}});
    b[0] = combine({{1.0, &phi_f[1]}, {-3.0, &phi_f[2]}, {4.0, &phi_f[3]}});
    b[1] = b[2] = ModeFunction();
    b[3] = combine({{-1.0, &phi_f[2]}, {4.0, &phi_f[3]}});
    b[4] = combine({{4.0, &phi_f[2]}, {-8.0, &phi_f[3]}});
    low[0] = combine({{1.0, &phi_f[1]}, {-2.0, &phi_f[2]}});
    low[1] = combine({{2.0, &phi_f[2]}});
  }
};

// "1 rad" for messages.
std::string rotation_limit_text() {
  char text[32];
  std::snprintf(text, sizeof text, "%g rad", kModalIntegratorMaxRotation);
  return text;
}

enum Flag { kOk = 0, kTooManySteps = -1, kStepTooSmall = -3, kNonFinite = -8, kTooFar = -20 };

class ModalExponential : public Integrator {
 public:
  bool init(const IntegratorOptions& o, OdeContext& c, N_Vector y0, std::string* error) {
    options_ = o;
    context_ = &c;
    const Model& model = c.model;
    n_ = model.n_dofs;
    if (n_ == 0) return fail(error, "the modal integrator needs at least one free body");
    if (n_ > kModalIntegratorMaxDofs)
      return fail(error, "the modal integrator handles up to " +
                             std::to_string(kModalIntegratorMaxDofs / kD) + " free bodies (" +
                             std::to_string(model.n_free()) +
                             " here): use bdf or dirk with the sparse solver");
    y13_.resize(model.n_states);
    acceleration_.resize(n_);
    ydot13_.resize(model.n_states);
    const double* y = N_VGetArrayPointer(y0);
    std::vector<double> reference(y, y + model.n_states);
    if (!choose_reference(model, reference, error)) return false;
    // The linearization: mass and symmetric tangent stiffness at the reference, at rest.
    Data& data = c.data;
    set_state(model, data, reference.data());
    compute_wrenches(model, data, 0.0);
    compute_tangent(model, data, 0.0, false);
    const Eigen::MatrixXd k = -Eigen::MatrixXd(stiffness_matrix(model, data));
    const Eigen::MatrixXd m(mass_matrix(model, data));
    Eigen::VectorXd values;
    if (!solve_dense_eigenproblem(0.5 * (k + k.transpose()), m, values, phi_))
      return fail(error, "the modal integrator's eigensolver failed");
    lambda_ = values.array();
    psi_t_ = (m * phi_).transpose();
    c0_.resize(model.n_free());
    a0_.resize(model.n_free());
    q0_.resize(model.n_free());
    for (int b = 0; b < model.n_free(); ++b) {
      const double* r = reference.data() + kS * b;
      c0_[b] = Vec3(r[0], r[1], r[2]);
      q0_[b] = Vec4(r[3], r[4], r[5], r[6]).normalized();
      a0_[b] = rotation_matrix<double>(q0_[b]);
    }
    from_states(y);
    linear_solver = "modal";
    stats_.jacobian_evaluations = 1;  // the tangent of the linearization
    return true;
  }

  int advance(double tout, double tstop, N_Vector y, double* t) override {
    const double target = std::min(tout, tstop);
    int flag = kOk;
    while (t_ < target && flag == kOk) flag = step_towards(target);
    to_states(N_VGetArrayPointer(y));
    *t = t_;
    return flag;
  }

  void restart(double t, N_Vector y) override {
    t_ = t;
    from_states(N_VGetArrayPointer(y));
  }

  SolverStats stats() const override { return stats_; }

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
      default:
        return "modal integrator flag " + std::to_string(flag);
    }
  }

 private:
  bool fail(std::string* error, const std::string& what) {
    *error = what;
    return false;
  }

  // The state linearized about (options_.about), written over `reference` (which holds the
  // initial state): the static equilibrium under the loads at t = 0, at rest, or the initial
  // state. False (with *error) when "static" was asked for and no equilibrium was found.
  bool choose_reference(const Model& model, std::vector<double>& reference, std::string* error) {
    if (options_.about == "initial") return true;
    if (!options_.about.empty() && options_.about != "static")
      return fail(error, "the modal integrator: unknown \"about\": \"" + options_.about +
                             "\" (expected \"static\" or \"initial\")");
    // From the model's initial configuration (solve_static starts there; so does y0).
    Data data(model);
    StaticOptions statics;
    statics.time = 0.0;
    statics.structure_cache = context_->structure_cache;
    const StaticResult equilibrium = solve_static(model, statics, data);
    if (std::chrono::steady_clock::now() > context_->deadline) {
      context_->timed_out = true;
      return fail(error,
                  "timeout: the run exceeded its max_seconds budget (in the modal "
                  "integrator's static solve)");
    }
    std::string why;
    if (!equilibrium.ok) {
      why = "no static equilibrium under the loads at t = 0 (" + equilibrium.message + ")";
    } else {
      for (int b = 0; b < model.n_free() && why.empty(); ++b) {
        const int body = model.free_bodies[b];
        const double* r = reference.data() + kS * b;
        const Mat3 a0 = rotation_matrix<double>(Vec4(r[3], r[4], r[5], r[6]));
        if (rotation_vector(data.pose[body].A * a0.transpose()).norm() >
            kModalIntegratorMaxRotation)
          why = "in the static equilibrium under the loads at t = 0, body \"" +
                model.bodies[body].name + "\" is turned more than " + rotation_limit_text() +
                " from its initial orientation";
      }
    }
    if (!why.empty()) {
      if (options_.about == "static")
        return fail(error, "the modal integrator: " + why +
                               "; \"about\": \"initial\" linearizes "
                               "about the initial state");
      warnings.push_back("the modal integrator linearized about the initial state: " + why +
                         (equilibrium.ok ? " (the run stops if a body turns more than " +
                                               rotation_limit_text() + " from there)"
                                         : ""));
      return true;
    }
    for (int b = 0; b < model.n_free(); ++b) {
      const int body = model.free_bodies[b];
      double* r = reference.data() + kS * b;
      const Vec3 c = centre(model, data, body);
      for (int j = 0; j < 3; ++j) r[j] = c(j);
      for (int j = 0; j < 4; ++j) r[3 + j] = data.q[body](j);
      for (int j = 7; j < kS; ++j) r[j] = 0.0;
    }
    return true;
  }

  // z from the 13 states of every free body.
  void from_states(const double* y) {
    Block x(n_, 2);
    for (size_t b = 0; b < c0_.size(); ++b) {
      const double* s = y + kS * b;
      const Mat3 a = rotation_matrix<double>(Vec4(s[3], s[4], s[5], s[6]));
      x.block<3, 1>(kD * b, 0) = Vec3(s[0], s[1], s[2]) - c0_[b];
      x.block<3, 1>(kD * b + 3, 0) = rotation_vector(a * a0_[b].transpose());
      x.block<3, 1>(kD * b, 1) = Vec3(s[7], s[8], s[9]);
      x.block<3, 1>(kD * b + 3, 1) =
          rotation_vector_rate(x.block<3, 1>(kD * b + 3, 0), a * Vec3(s[10], s[11], s[12]));
    }
    multiply(psi_t_, x, z_);
    multiply(phi_, z_, x_);
  }

  // Physical coordinates x = Phi z into the 13 states; false (with far_body_ set) when a body
  // turned too far and `check`; all bodies are written either way.
  bool states_of(const Block& x, double* y, bool check = true) {
    bool within = true;
    for (size_t b = 0; b < c0_.size(); ++b) {
      double* s = y + kS * b;
      const Vec3 theta = x.block<3, 1>(kD * b + 3, 0);
      if (check && within && !(theta.norm() <= kModalIntegratorMaxRotation)) {
        far_body_ = static_cast<int>(b);
        within = false;
      }
      Vec4 q = quat_multiply(quat_from_rotation_vector(theta), q0_[b]);
      q /= q.norm();
      const Mat3 a = rotation_matrix<double>(q);
      const Vec3 c = c0_[b] + x.block<3, 1>(kD * b, 0);
      const Vec3 w = a.transpose() * angular_velocity(theta, x.block<3, 1>(kD * b + 3, 1));
      for (int j = 0; j < 3; ++j) {
        s[j] = c(j);
        s[7 + j] = x(kD * b + j, 1);
        s[10 + j] = w(j);
      }
      for (int j = 0; j < 4; ++j) s[3 + j] = q(j);
    }
    return within;
  }

  // The accepted state (a rotation past the limit is reported by the next step that uses it).
  void to_states(double* y) { states_of(x_, y, false); }

  // N(t, z): everything but the modes' linear part, in modal coordinates; x = Phi z is given.
  // False when the forces are not finite or a body turned too far.
  bool nonlinear(double t, const Block& z, const Block& x, Block& out, int* flag) {
    if (!states_of(x, y13_.data())) {
      *flag = kTooFar;
      return false;
    }
    state_derivative(context_->model, context_->data, t, y13_.data(), ydot13_.data());
    ++stats_.rhs_evaluations;
    // The accelerations (dv/dt, d^2 theta/dt^2).
    for (size_t b = 0; b < c0_.size(); ++b) {
      const double* s = y13_.data() + kS * b;
      const double* d = ydot13_.data() + kS * b;
      for (int j = 0; j < kS; ++j)
        if (!std::isfinite(d[j])) {
          *flag = kNonFinite;
          return false;
        }
      const Mat3 a = rotation_matrix<double>(Vec4(s[3], s[4], s[5], s[6]));
      acceleration_.segment<3>(kD * b) = Vec3(d[7], d[8], d[9]);
      acceleration_.segment<3>(kD * b + 3) =
          rotation_vector_acceleration(x.block<3, 1>(kD * b + 3, 0), x.block<3, 1>(kD * b + 3, 1),
                                       a * Vec3(d[10], d[11], d[12]));
    }
    out.resize(n_, 2);
    out.col(0).setZero();
    multiply_vector(psi_t_, acceleration_.data(), out.col(1).data());
    out.col(1).array() += lambda_ * z.col(0).array();
    return true;
  }

  // One step of size f.h from (t, z) into `out`; n0 = N(t, z) is given.
  bool step(const StepFunctions& f, double t, const Block& z, const Block& n0, Block& out,
            int* flag) {
    constexpr int s = StepFunctions::kStages;
    stage_n_[0] = n0;
    for (int i = 1; i < s; ++i) {
      Block zi = Block::Zero(n_, 2);
      apply_add(StepFunctions::c[i] == 1.0 ? f.e_full : f.e_half, lambda_, z, zi);
      for (int j = 0; j < i; ++j) {
        if (f.a[i][j].empty()) continue;
        apply_add(f.a[i][j], lambda_, f.h * stage_n_[j], zi);
      }
      multiply(phi_, zi, xi_);
      if (!nonlinear(t + StepFunctions::c[i] * f.h, zi, xi_, stage_n_[i], flag)) return false;
    }
    out = Block::Zero(n_, 2);
    apply_add(f.e_full, lambda_, z, out);
    for (int j = 0; j < s; ++j)
      if (!f.b[j].empty()) apply_add(f.b[j], lambda_, f.h * stage_n_[j], out);
    return true;
  }

  // Weighted RMS norm of a modal error dz, measured in the physical states (x: rtol |c| + atol
  // for positions, rtol + atol for rotations; u: rtol |u| + atol) at the physical state x.
  double error_norm(const Block& dz, const Block& x) {
    multiply(phi_, dz, e_);
    const Block& e = e_;
    double sum = 0.0;
    for (size_t b = 0; b < c0_.size(); ++b)
      for (int j = 0; j < kD; ++j) {
        const Eigen::Index r = kD * static_cast<Eigen::Index>(b) + j;
        const double wx = j < 3 ? options_.rtol * std::abs(c0_[b](j) + x(r, 0)) + options_.atol
                                : options_.rtol + options_.atol;
        const double wu = options_.rtol * std::abs(x(r, 1)) + options_.atol;
        sum += (e(r, 0) / wx) * (e(r, 0) / wx) + (e(r, 1) / wu) * (e(r, 1) / wu);
      }
    return std::sqrt(sum / (2.0 * static_cast<double>(n_)));
  }

  // The error estimate is the distance to the embedded second-order solution, O(h^3): the step
  // controller's exponent. (Measured on the reference cantilever against step doubling with a
  // Richardson estimate of the fourth-order error: at errors near 1e-6 the embedded estimate
  // needed 16k right-hand sides at N = 40 where step doubling needed ~30k, and 5.6k vs 7.9k at
  // N = 10: with the order reduction on fine chains, the low-order estimate is the truer one.)
  static constexpr double kExponent = 1.0 / 3.0;

  // Advances by one accepted step (or to `target`). Returns a flag.
  int step_towards(double target) {
    if (context_->should_stop()) return kTooManySteps;
    if (stats_.steps >= options_.max_steps) return kTooManySteps;
    int flag = kOk;
    Block n0(n_, 2);
    try {
      if (!nonlinear(t_, z_, x_, n0, &flag)) return fail_flag(flag);
      if (h_ <= 0.0) h_ = options_.initial_step > 0.0 ? options_.initial_step : (target - t_);
      for (int attempt = 0;; ++attempt) {
        double h = std::min(h_, target - t_);
        if (options_.max_step > 0.0) h = std::min(h, options_.max_step);
        // Land on the target instead of leaving a sliver.
        if (t_ + 1.05 * h >= target) h = target - t_;
        if (!(h > 1e-14 * std::max(1.0, std::abs(t_)))) return kStepTooSmall;
        full_.compute(h, lambda_);
        Block next, low;
        int sflag = kOk;
        const bool ok = step(full_, t_, z_, n0, next, &sflag);
        double err = 0.0;
        if (ok) {
          // The embedded solution of order 2 from stages 1 and 2.
          low = Block::Zero(n_, 2);
          apply_add(full_.e_full, lambda_, z_, low);
          apply_add(full_.low[0], lambda_, h * stage_n_[0], low);
          apply_add(full_.low[1], lambda_, h * stage_n_[1], low);
          multiply(phi_, next, x_next_);
          err = error_norm(next - low, x_next_);
          if (!std::isfinite(err)) err = 1e10;
        } else if (sflag == kNonFinite) {
          // Perhaps a trial state too far out: retry smaller before giving up.
          if (attempt >= 10) return fail_flag(sflag);
          err = 1e10;
        } else {
          return fail_flag(sflag);
        }
        if (err <= 1.0) {
          t_ = (h == target - t_) ? target : t_ + h;
          z_ = next;
          x_.swap(x_next_);
          ++stats_.steps;
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

  int fail_flag(int flag) {
    if (flag == kTooFar && far_body_ >= 0) {
      const Model& model = context_->model;
      detail_ = "body \"" + model.bodies[model.free_bodies[far_body_]].name +
                "\" turned more than " + rotation_limit_text() +
                " from the orientation it is linearized about: the modal integrator is for "
                "small motions about one configuration; use bdf or dirk";
    }
    return flag;
  }

  IntegratorOptions options_;
  OdeContext* context_ = nullptr;
  Eigen::Index n_ = 0;
  Eigen::MatrixXd phi_, psi_t_;  // x = Phi z, z = Psi^T x
  Eigen::ArrayXd lambda_;
  std::vector<Vec3> c0_;
  std::vector<Vec4> q0_;
  std::vector<Mat3> a0_;
  Block z_, x_;                   // the accepted state, modal and physical (x_ = Phi z_)
  Block xi_, x_next_, e_;         // work space: a stage's physical state, a trial step's, its error
  Eigen::VectorXd acceleration_;  // work space: the physical accelerations of a stage
  double t_ = 0.0, h_ = 0.0;
  StepFunctions full_;
  Block stage_n_[StepFunctions::kStages];
  std::vector<double> y13_, ydot13_;
  SolverStats stats_;
  int far_body_ = -1;
  std::string detail_;
};

}  // namespace

std::unique_ptr<Integrator> make_modal_integrator(const IntegratorOptions& options,
                                                  OdeContext& context, N_Vector y0,
                                                  std::string* error) {
  auto integrator = std::make_unique<ModalExponential>();
  if (!integrator->init(options, context, y0, error)) return nullptr;
  return integrator;
}

}  // namespace beamrail
