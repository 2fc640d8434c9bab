#include "core/analysis/auto_integrator.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/analysis/explicit_stability.hpp"
#include "core/analysis/modal_coordinates.hpp"
#include "core/analysis/modal_integrator.hpp"
#include "core/analysis/modal_step_bounds.hpp"
#include "core/model/element_kinds.hpp"

namespace beamrail {
namespace {

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", v);
  return text;
}

SolverStats sum(const SolverStats& a, const SolverStats& b) {
  SolverStats s = a;
  s.steps += b.steps;
  s.rhs_evaluations += b.rhs_evaluations;
  s.jacobian_evaluations += b.jacobian_evaluations;
  s.nonlinear_iterations += b.nonlinear_iterations;
  s.nonlinear_failures += b.nonlinear_failures;
  s.error_test_failures += b.error_test_failures;
  return s;
}

// The quoted name in a message ("body \"tip\" turned ..."), or "".
std::string quoted(const std::string& text) {
  const size_t a = text.find('"');
  const size_t b = a == std::string::npos ? a : text.find('"', a + 1);
  return b == std::string::npos ? "" : text.substr(a, b - a + 1);
}

class AutoIntegrator : public Integrator {
 public:
  bool init(const IntegratorOptions& o, OdeContext& c, SUNContext sunctx, N_Vector y0,
            std::string* error) {
    options_ = o;
    context_ = &c;
    sunctx_ = sunctx;
    const Model& model = c.model;
    if (model.n_free() == 0)
      return start_method(IntegratorMethod::kBdf, "", 0.0, y0, "the scene has no free body", error);
    // A moving support leaves any one linearization: an A-stable implicit method, whose steps the
    // undamped axial modes of a spinning beam do not hold down. On studies/spin_up.json (10
    // segments, 30 s, rtol 1e-7) bdf took 582k steps (13.4 s: its higher orders are unstable for
    // them), ESDIRK547 45k (4.9 s, 6e-5 off a tight run), the default DIRK table 12k (3.2 s, 1e-7
    // off).
    if (!model.driven_bodies.empty())
      return start_method(IntegratorMethod::kDirk, "", 0.0, y0,
                          "body \"" + model.bodies[model.driven_bodies.front()].name +
                              "\" moves as prescribed: its supports move, no one configuration "
                              "to vibrate about",
                          error);
    // A damped grounded mechanism (a pendulum on a joint, a carriage on a rail: a body not held by
    // beams and fixed joints to the ground, and no floating part): dirk. Along a mechanism's large
    // motion the relinearized modal phases' error can grow past their estimates (an adversarial
    // review, 2026-11-29: a pendulum on a revolute joint 38 rtol off at rtol 1e-4 over 131
    // phases), which on a scene that keeps its energy the energy check reports; damping takes that
    // check away. Handing over to an implicit method at the first rotation limit instead was
    // tried: bdf started mid-swing was erratic at loose rtol (a damped spherical pendulum 20.8
    // rtol at rtol 1e-4, from the start 0.0017). Floating parts (relinearized, or followed in a
    // turning frame) keep the modal method: there bdf drifts (a damped tumbling pair 10 to 18
    // rtol, the modal method 0.04 to 0.8).
    // Why dirk and not bdf (measured 2026-11-30 against Verner at rtol 1e-11, 0.1 s,
    // docs/transient_measurements.md "Damped mechanisms"): bdf left flexible pendulums (a rod of 5
    // mm steel between an arm on a joint and a 0.1 kg tip) 8 to 51 rtol off at rtol 1e-4, silent,
    // and took 1.4 to 3.3 million steps (8 to 54 s) at rtol 1e-6, where their barely damped fast
    // modes keep its higher orders unstable; dirk (A-stable) was within 0.004 rtol at rtol 1e-4 and
    // 1e-6 in 0.08 to 0.6 s, and 0.01 at 1e-8 (1.7 to 26 s, bdf 8.8 to 54 s).
    if (largest_damping(model) > 0.0 && !held_by_beams(model) && floating_parts(model).empty())
      return start_method(IntegratorMethod::kDirk, "", 0.0, y0,
                          "damping, and bodies that move as a mechanism (not held by beams and "
                          "fixed joints to the ground): along a mechanism's large motion the "
                          "modal method's relinearized phases have no check under damping; dirk "
                          "is A-stable where the barely damped fast modes hold bdf's higher "
                          "orders unstable",
                          error);
    choose_band_ =
        !(o.max_frequency_hz > 0.0) && (o.choose_band || model.n_dofs >= kAutoChosenBandDofs);
    // A small scene's eigenproblem is cheap: relinearize sooner from the start.
    rotation_limit_ = std::clamp(
        kAutoRelinearizeRotation * static_cast<double>(model.n_dofs) / kAutoFullRotationDofs,
        kAutoMinRelinearizeRotation, kAutoRelinearizeRotation);
    IntegratorOptions m = modal_options();
    m.about = o.about;
    std::string why;
    std::unique_ptr<Integrator> modal = make_modal_integrator(m, c, y0, &why, 0.0);
    if (!modal) {
      if (c.timed_out || c.interrupted) {
        *error = why;
        return false;
      }
      return start_method(IntegratorMethod::kBdf, "", 0.0, y0,
                          "the modal method could not start: " + why, error);
    }
    std::string reason = std::to_string(model.n_free()) + " free bod" +
                         (model.n_free() == 1 ? "y" : "ies") +
                         ": small motions about one configuration, each mode's vibration exact";
    if (double own = 0.0, coupling = 0.0; modal_damping(*modal, &own, &coupling) && own > 0.0) {
      // Each mode's own damping is exact in its block; what couples the modes stays explicit.
      if (const std::string why = coupled_damping(*modal); !why.empty())
        return start_method(IntegratorMethod::kDirk, "", 0.0, y0, why, error);
      const double step = coupling > 0.0 ? 2.5 / coupling : 0.0;
      reason += "; each mode's damping exact (up to " + number(own) + " 1/s)";
      if (step > 0.0)
        reason += ", their coupling (" + number(coupling) + " 1/s) allows steps up to " +
                  number(step) + " s";
    }
    if (const double rate = modal_frame_rate(*modal); rate > 0.0)
      reason += "; floating and spinning: followed in a frame turning with it (" + number(rate) +
                " rad/s, the fastest part)";
    if (const std::string band = modal_band_choice(*modal); !band.empty()) reason += "; " + band;
    // Where the loads push a free body or mechanism along a direction without stiffness no
    // equilibrium exists, and the initial state is auto's choice, not a fallback: the reason
    // says so, without the modal method's warning.
    const InitialLinearization initial = modal_initial_linearization(*modal);
    first_modal_warnings_ = warnings.size();
    for (const std::string& w : modal->warnings)
      if (!initial.no_equilibrium || w.find(initial.because) == std::string::npos)
        warnings.push_back(w);
    first_modal_warnings_end_ = warnings.size();
    const std::string& initial_because = initial.because;
    const bool about_initial = o.about == "initial" || !initial_because.empty();
    band_hz = modal->band_hz;
    mechanism_ = moves_as_mechanism(model) && !(o.max_frequency_hz > 0.0);
    limit_inertia(*modal);
    current_ = std::move(modal);
    modal_ = true;
    linear_solver = "modal";
    record(0.0, "modal",
           reason + (!initial_because.empty()
                         ? " (linearized about the initial state: " + initial_because + ")"
                     : about_initial ? " (linearized about the initial state)"
                                     : " (linearized about the equilibrium at t = 0)"));
    return true;
  }

  int advance(double tout, double tstop, N_Vector y, double* t) override {
    for (bool switched = false;; switched = true) {
      // A modal phase that failed after reaching the target (a band's quasi-static part at the
      // state reached) hands over there: the implicit or explicit method starts with the next
      // call (SUNDIALS refuses a stop time at its start).
      if (switched && !modal_ && *t >= std::min(tout, tstop)) return 0;
      if (modal_ && mechanism_) set_modal_held_limit(*current_, held_limit());
      const int flag = current_->advance(tout, tstop, y, t);
      if (modal_ && (flag == kModalStepTooSmall || flag == kModalNonFinite) &&
          !context_->timed_out && !context_->interrupted && context_->callback_error.empty()) {
        // The modal method failed where an implicit one may not (a motion too far from the
        // linearization for its explicit remainder, a band's quasi-static iteration that does
        // not converge): the run goes on from the last accepted state, and says why. A band auto
        // chose first widens to every mode where the dense eigensolver gives them: a 100-segment
        // cantilever with a 3 kg tip under 100 N (a 0.16 m deflection), whose 76-mode band failed
        // at 3 us, ran dirk in 56 s at rtol 1e-6 (0.07 / 0.56 times its tolerance in the centres
        // / orientations); every mode took 17.6 s (1e-4 / 0.03).
        if (choose_band_ && current_->band_hz > 0.0 &&
            context_->model.n_dofs <= kModalDenseBandMaxDofs) {
          if (!widen(
                  *t, y,
                  "the modal method failed in the band it chose (" + current_->failure(flag) + ")",
                  0.0, false))
            return kAutoFailed;
          continue;
        }
        withdraw_stepless_modal_warnings(before_.steps == 0 && current_->stats().steps == 0);
        before_ = sum(before_, current_->stats());
        std::string error;
        if (!start_method(IntegratorMethod::kDirk, kAutoImplicitTable, *t, y,
                          "the modal method failed (" + current_->failure(flag) + ")", &error))
          return fail(error);
        continue;
      }
      if (flag == kModalInertia && modal_) {
        if (!widen_band(*t, y)) return kAutoFailed;
        continue;
      }
      if (flag == kModalHeld && modal_) {
        const HeldSteps stretch = modal_held_steps(*current_);
        before_ = sum(before_, current_->stats());
        std::string error;
        if (!start_method(IntegratorMethod::kDirk, "", *t, y,
                          "a mechanism whose modal steps its stiff modes' ringing held short (" +
                              std::to_string(stretch.held) + " of its last " +
                              std::to_string(stretch.steps) + " steps at less than " +
                              number(kMechanismHeldShare) +
                              " of the step its estimates asked for): dirk steps over that "
                              "ringing",
                          &error))
          return fail(error);
        continue;
      }
      if (flag != kModalTooFar || !modal_) return flag;
      const std::string who = quoted(current_->failure(flag));
      const long steps = current_->stats().steps;
      if (const std::string why = explicit_instead(*t, steps); !why.empty()) {
        before_ = sum(before_, current_->stats());
        std::string error;
        if (!start_method(IntegratorMethod::kErk, kAutoExplicitTable, *t, y, why, &error))
          return fail(error);
        continue;
      }
      short_runs_ = steps < kAutoMinStepsPerLinearization ? short_runs_ + 1 : 0;
      short_run_steps_ = short_runs_ == 1 ? steps : std::max(short_run_steps_, steps);
      const bool no_step_yet = before_.steps == 0 && steps == 0;
      before_ = sum(before_, current_->stats());
      const double turned = rotation_limit_;
      if (short_runs_ >= 3 && rotation_limit_ < kAutoRelinearizeRotation) {
        // A fast spin, not a stiff remainder: back to the full limit before giving up, and not
        // down to this one again.
        smallest_limit_ = std::min(kAutoRelinearizeRotation, 2.0 * rotation_limit_);
        rotation_limit_ = kAutoRelinearizeRotation;
        short_runs_ = 0;
      } else if (short_runs_ >= 3) {
        withdraw_stepless_modal_warnings(no_step_yet);
        // No step in any of them: a body beyond the limit at once (a band's quasi-static part
        // at the state itself), not a fast turn.
        const std::string why = short_run_steps_ == 0
                                    ? "relinearizing without a step, three times running (body " +
                                          who + " " + number(rotation_limit_) +
                                          " rad from each linearization at once)"
                                    : "relinearizing every " + std::to_string(short_run_steps_) +
                                          " steps or sooner (body " + who + " turns " +
                                          number(rotation_limit_) + " rad that fast)";
        std::string error;
        if (!start_method(IntegratorMethod::kDirk, kAutoImplicitTable, *t, y, why, &error))
          return fail(error);
        continue;
      }
      // Relinearizing (a dense eigenproblem, ~n^3) cheap against the phase's steps (~n^2 each):
      // sooner next time, which lets the remainder the modal method treats explicitly stay
      // small (a stiff hinge swinging: 98,663 steps for 0.3 s at 0.5 rad, 17,207 at 0.02).
      const double dofs = static_cast<double>(context_->model.n_dofs);
      if (short_runs_ == 0 && dofs < kAutoRelinearizeCostRatio * static_cast<double>(steps))
        rotation_limit_ = std::max(smallest_limit_, 0.5 * rotation_limit_);
      std::string why;
      IntegratorOptions m = modal_options();
      m.about = "initial";
      m.initial_step = modal_step_size(*current_);  // the motion goes on at its pace
      std::unique_ptr<Integrator> next = make_modal_integrator(m, *context_, y, &why, *t);
      if (!next) {
        if (context_->timed_out || context_->interrupted) return fail(why);
        std::string error;
        if (!start_method(IntegratorMethod::kDirk, kAutoImplicitTable, *t, y,
                          "the modal method could not relinearize: " + why, &error))
          return fail(error);
        continue;
      }
      if (const std::string coupled = coupled_damping(*next); !coupled.empty()) {
        // Relinearized where damping couples the modes more (a deformed structure).
        std::string error;
        if (!start_method(IntegratorMethod::kDirk, "", *t, y, coupled, &error)) return fail(error);
        continue;
      }
      if (modal_mechanism_bound(*current_)) hold_modal_mechanism_bound(*next);
      continue_modal_held_steps(*current_, *next);
      next->restart(*t, y);
      band_hz = std::max(band_hz, next->band_hz);
      absorb_inertia();
      limit_inertia(*next);
      current_ = std::move(next);
      phase_start_ = *t;
      record(*t, "modal",
             "body " + who + " turned " + number(turned) + " rad from the linearization" +
                 (modal_frame_rate(*current_) > 0.0 ? " (in the frame turning with its part)"
                                                    : std::string()) +
                 ": relinearized about this state" +
                 (choose_band_ ? "; " + modal_band_choice(*current_) : std::string()),
             true);
    }
  }

  void restart(double t, N_Vector y) override { current_->restart(t, y); }

  SolverStats stats() const override { return sum(before_, current_->stats()); }

  std::string failure(int flag) const override {
    if (flag == kAutoFailed) return failure_;
    return current_->failure(flag);
  }

  // The held steps after which a mechanism's modal phase goes on with dirk (kAutoHeldSteps, and
  // kAutoHeldWork over the products' cost, the degrees of freedom squared).
  long held_limit() const {
    const double dofs = static_cast<double>(context_->model.n_dofs);
    return std::max(kAutoHeldSteps, static_cast<long>(std::ceil(kAutoHeldWork / (dofs * dofs))));
  }

  // The dropped inertia of the band-limited modal phases: their drifts add up.
  std::vector<std::string> closing_warnings() const override {
    QuasiStaticInertia q = inertia_;
    if (QuasiStaticInertia now;
        current_->stats().steps > 0 && modal_quasi_static_inertia(*current_, &now))
      add(q, now);
    if (!(q.drift > options_.rtol)) return {};
    return {quasi_static_inertia_warning(q)};
  }

  std::vector<MethodPhase> phases(long* count) const override {
    *count = count_;
    std::vector<MethodPhase> out = first_;
    if (count_ > static_cast<long>(first_.size())) out.push_back(last_);
    return out;
  }

 private:
  static constexpr int kAutoFailed = -1001;

  // Why bdf, when the damping that couples a modal integrator's modes (explicit in it) damps
  // beyond kAutoMaxDampingRatio of its fastest mode's critical damping; else "".
  static std::string coupled_damping(const Integrator& modal) {
    double own = 0.0, coupling = 0.0, lowest = 0.0, highest = 0.0;
    if (!modal_damping(modal, &own, &coupling) || !(coupling > 0.0) ||
        !modal_spectrum(modal, &lowest, &highest) || !(highest > 0.0))
      return "";
    const double ratio = 0.5 * coupling / std::sqrt(highest);
    if (!(ratio > kAutoMaxDampingRatio)) return "";
    return "damping that couples the modes (" + number(coupling) + " 1/s, " + number(ratio) +
           " of the fastest mode's critical damping; the modes' own is exact) would hold the "
           "modal method's steps below " +
           number(2.5 / coupling) + " s; dirk (L-stable) steps over the decayed modes";
  }

  // Why an explicit Runge-Kutta method goes on from t, when the modal phase that ended there
  // (`steps` steps, every mode integrated) moved a mechanism, or a part followed in a turning
  // frame, with steps its error estimates held below kAutoExplicitResolved of the bound on
  // w_max h there (core/analysis/modal_step_bounds.hpp); else "".
  std::string explicit_instead(double t, long steps) const {
    if (!(steps > 0) || current_->band_hz > 0.0) return "";
    const bool turning = modal_frame_rate(*current_) > 0.0;
    if (!mechanism_ && !turning) return "";
    double lowest = 0.0, highest = 0.0;
    if (!modal_spectrum(*current_, &lowest, &highest) || !(highest > 0.0)) return "";
    const double wh = std::sqrt(highest) * (t - phase_start_) / static_cast<double>(steps);
    double bound = std::numeric_limits<double>::infinity();
    if (mechanism_) bound = mechanism_step_bound(options_.rtol);
    if (turning) bound = std::min(bound, turning_step_bound(options_.rtol));
    if (!(wh < kAutoExplicitResolved * bound)) return "";
    return std::string(mechanism_ ? "a mechanism" : "a part turning with its frame") +
           " whose modal steps resolve its fastest mode (" + number(std::sqrt(highest)) +
           " rad/s times the steps from t = " + number(phase_start_) + " s: " + number(wh) +
           " on average, the bound at rtol " + number(bound) +
           "): an explicit Runge-Kutta method is not held shorter by it, and its error follows "
           "rtol along the large motion, where the modal method's estimates were measured to "
           "miss it";
  }

  IntegratorOptions modal_options() const {
    IntegratorOptions m = options_;
    m.method = IntegratorMethod::kModal;
    m.table.clear();
    m.max_rotation = rotation_limit_;
    m.choose_band = choose_band_;
    if (widened_) m.max_frequency_hz = widened_hz_;
    m.max_steps = std::max(1L, options_.max_steps - before_.steps);
    return m;
  }

  static void add(QuasiStaticInertia& sum, const QuasiStaticInertia& phase) {
    sum.band_hz = std::max(sum.band_hz, phase.band_hz);
    sum.ratio = std::max(sum.ratio, phase.ratio);
    sum.drift += phase.drift;
    sum.t = phase.t;
  }

  // A band auto chose (or widened) ends its phase when its dropped inertia passes its share of
  // what is left of rtol (kAutoInertiaShare).
  // Where the phases before have used that share up, the next stops once it has settled (a
  // cantilever bent by a 300 N step, relinearized every 0.01 s as its tip turned, each phase too
  // short to settle: its bands dropped 0.19 of the kinetic energy, and the run ended 560 rtol
  // off, warned; tests/core/analysis/transient_auto_band_test.cpp). Its settling counts from the
  // first phase of the band auto chose.
  void limit_inertia(Integrator& modal) const {
    if (!choose_band_ && !widened_) return;
    const double left = kAutoInertiaShare * (options_.rtol - inertia_.drift);
    set_modal_inertia_limit(modal, left > 0.0 ? left : std::numeric_limits<double>::min());
    if (choose_band_) set_modal_settling_start(modal, 0.0);
  }

  // The modes a chosen band kept quasi-static carry inertia the run would lose: the run goes on
  // from (t, y) with every mode, or above kModalDenseBandMaxDofs with a band kAutoBandWidening
  // times wider, linearized about this state; false (failure_ set) when no modal method starts
  // and dirk does not either.
  bool widen_band(double t, N_Vector y) {
    QuasiStaticInertia q = inertia_;  // what the band's phases before dropped too
    if (QuasiStaticInertia now; modal_quasi_static_inertia(*current_, &now)) add(q, now);
    const bool every = context_->model.n_dofs <= kModalDenseBandMaxDofs;
    // Stopped before its first step: by the pull measured at its start
    // (ModalExponential::measure_pull), nothing dropped yet.
    const bool before = current_->stats().steps == 0;
    const std::string why =
        "the modes above the " + number(q.band_hz) + " Hz band, kept quasi-static, " +
        (before ? "would move with " + number(q.ratio) +
                      " of its kinetic energy (pulled along at second order on the way to the "
                      "band's static response: inertia the band would leave out, an error of "
                      "about " +
                      number(q.drift) + " of the motion)"
                : "moved with " + number(q.ratio) +
                      " of its kinetic energy (inertia the band leaves out: an error estimated "
                      "at " +
                      number(q.drift) + " of the motion by t = " + number(t) + " s)");
    return widen(t, y, why, every ? 0.0 : kAutoBandWidening * q.band_hz, true);
  }

  // Goes on from (t, y) with a band of `hz` (0: every mode), linearized about this state, starting
  // at the last phase's step (`same_pace`) or its own; false (failure_ set) when no modal method
  // starts and dirk does not either.
  bool widen(double t, N_Vector y, const std::string& why, double hz, bool same_pace) {
    const bool every = !(hz > 0.0);
    before_ = sum(before_, current_->stats());
    choose_band_ = false;
    widened_ = true;
    widened_hz_ = hz;
    IntegratorOptions m = modal_options();
    m.about = "initial";
    if (same_pace) m.initial_step = modal_step_size(*current_);
    std::string error;
    std::unique_ptr<Integrator> next = make_modal_integrator(m, *context_, y, &error, t);
    if (!next) {
      if (!context_->timed_out && !context_->interrupted &&
          start_method(IntegratorMethod::kDirk, kAutoImplicitTable, t, y,
                       why + "; the modal method with more modes could not start: " + error,
                       &error))
        return true;
      fail(error);
      return false;
    }
    next->restart(t, y);
    band_hz = std::max(band_hz, next->band_hz);
    absorb_inertia();
    limit_inertia(*next);
    current_ = std::move(next);
    phase_start_ = t;
    record(t, "modal",
           why +
               (every ? ": every mode integrated from here"
                      : ": a band of " + number(hz) + " Hz from here") +
               ", linearized about this state");
    return true;
  }

  // Keeps what the current phase dropped before it ends.
  // A phase that took no step dropped nothing (its pull measured at the start: its drift is a
  // forecast, not the run's).
  void absorb_inertia() {
    if (current_->stats().steps == 0) return;
    if (QuasiStaticInertia q; modal_quasi_static_inertia(*current_, &q)) add(inertia_, q);
  }

  // Modal phases that ran no step before a fallback (the first, and those relinearized at once
  // as a body turned) left nothing of their model in the run: what the first's set-up warned of
  // (its band, its linearization) does not apply, and is withdrawn when `stepless`.
  void withdraw_stepless_modal_warnings(bool stepless) {
    if (!stepless) return;
    warnings.erase(warnings.begin() + static_cast<long>(first_modal_warnings_),
                   warnings.begin() + static_cast<long>(first_modal_warnings_end_));
    first_modal_warnings_end_ = first_modal_warnings_;
  }

  int fail(const std::string& why) {
    failure_ = why;
    return kAutoFailed;
  }

  // Goes on with another method (bdf, dirk, erk) from (t, y).
  bool start_method(IntegratorMethod method, const std::string& table, double t, N_Vector y,
                    const std::string& reason, std::string* error) {
    IntegratorOptions o = options_;
    o.method = method;
    o.table = table;
    o.about.clear();
    o.max_frequency_hz = 0.0;
    o.choose_band = false;
    o.max_rotation = 0.0;
    o.steps_before = before_.steps;
    std::unique_ptr<Integrator> next = make_integrator(o, *context_, sunctx_, y, error);
    if (!next) return false;
    if (t > 0.0) next->restart(t, y);
    if (current_) absorb_inertia();
    for (const std::string& w : next->warnings) warnings.push_back(w);
    current_ = std::move(next);
    modal_ = false;
    linear_solver = current_->linear_solver;
    nnz = current_->nnz;
    const std::string name = method_name(method);
    record(t, table.empty() ? name : name + " " + table, reason);
    return true;
  }

  void record(double t, const std::string& method, const std::string& reason,
              bool relinearized = false) {
    MethodPhase p{t, method, reason, relinearized};
    if (count_ > 0 && phase_started) phase_started(p);
    if (first_.size() + 1 < kMaxRecordedPhases)
      first_.push_back(std::move(p));
    else
      last_ = std::move(p);
    ++count_;
  }

  IntegratorOptions options_;
  OdeContext* context_ = nullptr;
  SUNContext sunctx_ = nullptr;
  std::unique_ptr<Integrator> current_;
  bool modal_ = false;
  bool mechanism_ = false;    // a body moves as a mechanism, no band of the user's
  double phase_start_ = 0.0;  // where the current modal phase started [s]
  bool choose_band_ = false;  // the modal method's band chosen for rtol
  bool widened_ = false;      // a chosen band was widened (widen_band): to widened_hz_
  double widened_hz_ = 0.0;   // [Hz]; 0: every mode
  int short_runs_ = 0;        // consecutive linearizations that lasted few steps
  long short_run_steps_ = 0;  // the most steps of one of them
  double rotation_limit_ = kAutoRelinearizeRotation;     // of the current linearization [rad]
  double smallest_limit_ = kAutoMinRelinearizeRotation;  // the limit halves down to this
  SolverStats before_;                                   // of the phases before the current one
  QuasiStaticInertia inertia_;  // the dropped inertia of the modal phases before the current one
  std::string failure_;         // why auto itself failed (kAutoFailed)
  // The warnings of the first modal phase's set-up: [first_modal_warnings_, .._end_).
  size_t first_modal_warnings_ = 0, first_modal_warnings_end_ = 0;
  std::vector<MethodPhase> first_;
  MethodPhase last_;
  long count_ = 0;
};

}  // namespace

std::unique_ptr<Integrator> make_auto_integrator(const IntegratorOptions& options,
                                                 OdeContext& context, SUNContext sunctx,
                                                 N_Vector y0, std::string* error) {
  auto integrator = std::make_unique<AutoIntegrator>();
  if (!integrator->init(options, context, sunctx, y0, error)) return nullptr;
  return integrator;
}

}  // namespace beamrail
