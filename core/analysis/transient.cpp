#include "core/analysis/transient.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <numbers>
#include <stdexcept>

#include "core/analysis/axial_force_watch.hpp"
#include "core/analysis/deformation_check.hpp"
#include "core/analysis/integrators.hpp"
#include "core/analysis/sundials_support.hpp"
#include "core/model/dynamics.hpp"
#include "core/model/forces.hpp"
#include "core/model/rotation.hpp"

namespace beamrail {
namespace {

TransientSample sample_at(const Model& model, Data& data, double t, const double* y) {
  set_state(model, data, y);
  set_driven_poses(model, data, t);
  compute_wrenches(model, data, t);
  TransientSample s;
  s.t = t;
  s.kinetic = kinetic_energy(model, data);
  s.elastic = data.elastic_energy;
  s.gravity = gravity_energy(model, data);
  return s;
}

// A time the integrators stop at: where a time function's factor or its slope jumps (the method
// restarts there), or an end of a smooth ramp (its slope and curvature are continuous: the method
// goes on without a restart). A step longer than a smooth ramp could pass over it unseen: a load
// pulse of two smooth ramps, 0.30 .. 0.35 s, on a cantilever at rest came out as no motion at
// all from every method, Verner 8(7) at rtol 1e-11 included (an adversarial review, 2026-11-29).
// Restarting there instead cost bdf its order at every ramp end: with 1,000 overlapping ramps
// its error at rtol 1e-6 went from 1.7e-5 to 1.6e-4 of the motion (the next review).
struct Stop {
  double t = 0.0;
  bool restart = true;
};

// A smooth ramp's stops: its ends and the times between that part it into this many, so that no
// step is longer than this part of it. Its factor s - sin(2 pi s) / (2 pi) equals a linear ramp's
// at s = 0, 1/2 and 1, the modal method's stage times over a step as long as the ramp: a load
// ramped smoothly over 15 ms from the start of a run with outputs every 50 ms was integrated as a
// linear ramp in one step, 1.47e-3 of the motion off at every rtol (1,470 rtol at 1e-6), ok and
// silent, its verification rerun taking the same step (an adversarial review, 2026-12-01; tests/
// core/analysis/transient_limits_test.cpp). With the stops the step control sees the curvature.
constexpr int kSmoothRampStops = 8;

// The stops of the time function f of a load or drive whose vector is not zero (a function
// that scales nothing neither stops nor holds the steps).
void append_stops(const TimeFunction& f, const Vec3& scaled, std::vector<Stop>& stops) {
  if (scaled.isZero(0.0)) return;
  std::vector<double> jumps;
  f.append_breakpoints(jumps);
  for (double t : jumps) stops.push_back({t, true});
  if (f.type == TimeFunction::Type::kSmoothRamp)
    for (int k = 0; k <= kSmoothRampStops; ++k)
      stops.push_back({f.from + (f.to - f.from) * k / kSmoothRampStops, false});
}

// The stops inside (0, t_end), in order, one per time (restarting if any there does).
std::vector<Stop> time_breakpoints(const Model& model, double t_end) {
  std::vector<Stop> all, inside;
  for (const Load& load : model.loads) append_stops(load.time, load.value, all);
  for (int i : model.driven_bodies) {  // a drive's velocity jumps or kinks there
    const PrescribedMotion& m = model.bodies[i].motion;
    append_stops(m.velocity_time, m.velocity, all);
    append_stops(m.angular_velocity_time, m.angular_velocity, all);
  }
  std::sort(all.begin(), all.end(), [](const Stop& a, const Stop& b) { return a.t < b.t; });
  for (const Stop& s : all) {
    if (!(s.t > 0.0 && s.t < t_end)) continue;
    if (!inside.empty() && !(s.t > inside.back().t))
      inside.back().restart = inside.back().restart || s.restart;
    else
      inside.push_back(s);
  }
  return inside;
}

}  // namespace

double highest_harmonic_hz(const Model& model) {
  double highest = 0.0;
  const auto consider = [&highest](const TimeFunction& f, const Vec3& scaled) {
    if (f.type == TimeFunction::Type::kHarmonic && !scaled.isZero(0.0))
      highest = std::max(highest, std::abs(f.frequency));
  };
  for (const Load& load : model.loads) consider(load.time, load.value);
  for (int i : model.driven_bodies) {
    const PrescribedMotion& m = model.bodies[i].motion;
    consider(m.velocity_time, m.velocity);
    consider(m.angular_velocity_time, m.angular_velocity);
  }
  return highest;
}

const char* method_name(IntegratorMethod method) {
  switch (method) {
    case IntegratorMethod::kBdf:
      return "bdf";
    case IntegratorMethod::kAdams:
      return "adams";
    case IntegratorMethod::kDirk:
      return "dirk";
    case IntegratorMethod::kErk:
      return "erk";
    case IntegratorMethod::kModal:
      return "modal";
    case IntegratorMethod::kAuto:
      return "auto";
  }
  return "?";
}

std::optional<IntegratorMethod> method_from_name(const std::string& name) {
  for (IntegratorMethod m :
       {IntegratorMethod::kBdf, IntegratorMethod::kAdams, IntegratorMethod::kDirk,
        IntegratorMethod::kErk, IntegratorMethod::kModal, IntegratorMethod::kAuto})
    if (name == method_name(m)) return m;
  return std::nullopt;
}

namespace {

// A free body's Euler parameters in its 13 states `s`, and their rate 1/2 L(q) w (w in body
// axes, as state_derivative).
Vec4 euler_parameters(const double* s) { return Vec4(s[3], s[4], s[5], s[6]); }
Vec4 euler_rate(const double* s) {
  return 0.5 * quat_left_product_matrix(euler_parameters(s)) * Vec3(s[10], s[11], s[12]);
}

// The path between two steps is looked at k - 1 times, evenly, k from kPathSamples doubled
// (up to kMostPathSamples) until what a path of acceleration a could pass its samples by unseen,
// a (h / k)^2 / 8, is below kPathShare of the smallest margin of the elements (element_margins)
// at the samples and the step's end: adams at rtol 1e-8 took one step of 0.42 s over a carriage
// 1 mm past its travel's end under 10 m/s^2 (its parabola is exact for adams), which eighths
// of the step passed by 3.4 mm.
constexpr int kPathSamples = 8;
constexpr int kMostPathSamples = 256;
constexpr double kPathShare = 0.25;

// The largest second derivatives [m/s^2, rad/s^2] of the cubic (state_between) of a step of
// length h from y0 to y1, at either end: of a body's centre, plus 2 |q''| (its angular
// acceleration) times `arm`, the longest centre -> attachment arm; and 2 |q''|.
std::pair<double, double> path_accelerations(const Model& model, double h, const double* y0,
                                             const double* y1, double arm) {
  double a_length = 0.0, a_angle = 0.0;
  for (int k = 0; k < model.n_free(); ++k) {
    const double* a = y0 + kStatesPerBody * k;
    const double* b = y1 + kStatesPerBody * k;
    const Vec3 du(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
    const Vec3 va(a[7], a[8], a[9]), vb(b[7], b[8], b[9]);
    const double centre = std::max((6.0 * du - h * (4.0 * va + 2.0 * vb)).norm(),
                                   (-6.0 * du + h * (2.0 * va + 4.0 * vb)).norm()) /
                          (h * h);
    const Vec4 qa = euler_parameters(a), qb = euler_parameters(b);
    const Vec4 ra = euler_rate(a), rb = euler_rate(b);
    const double turn = 2.0 *
                        std::max((6.0 * (qb - qa) - h * (4.0 * ra + 2.0 * rb)).norm(),
                                 (-6.0 * (qb - qa) + h * (2.0 * ra + 4.0 * rb)).norm()) /
                        (h * h);
    a_length = std::max(a_length, centre + turn * arm);
    a_angle = std::max(a_angle, turn);
  }
  return {a_length, a_angle};
}

// How the time a path between two steps leaves an element's range is located (path_exit).
constexpr int kPathExitScan = 64;
constexpr int kPathExitBisections = 40;

// How far outside an element's range the path between two steps must be for the run to end
// there, in multiples of its tolerance (rtol x its length + atol; rtol + atol radians).
constexpr double kPathTolerances = 10.0;

// The state at t0 + s (t1 - t0) on the cubic through two accepted states' positions and their
// rates (Hermite: exact on a path of constant acceleration, off by h^4 / 384 of the fourth
// derivative): each free body's displacement from its velocities, its Euler parameters from
// their rates 1/2 L(q) w (normalized), its velocities linear between the two.
void state_between(const Model& model, double t0, const double* y0, double t1, const double* y1,
                   double s, double* out) {
  const double h = t1 - t0;
  const double h00 = (1.0 + 2.0 * s) * (1.0 - s) * (1.0 - s), h10 = s * (1.0 - s) * (1.0 - s);
  const double h01 = s * s * (3.0 - 2.0 * s), h11 = s * s * (s - 1.0);
  for (int k = 0; k < model.n_free(); ++k) {
    const double* a = y0 + kStatesPerBody * k;
    const double* b = y1 + kStatesPerBody * k;
    double* o = out + kStatesPerBody * k;
    for (int i = 0; i < 3; ++i)
      o[i] = h00 * a[i] + h10 * h * a[7 + i] + h01 * b[i] + h11 * h * b[7 + i];
    const Vec4 qa = euler_parameters(a), qb = euler_parameters(b);
    const Vec4 ra = euler_rate(a), rb = euler_rate(b);
    const Vec4 q = h00 * qa + h10 * h * ra + h01 * qb + h11 * h * rb;
    const Vec4 unit = q / q.norm();
    for (int i = 0; i < 4; ++i) o[3 + i] = unit[i];
    for (int i = 7; i < kStatesPerBody; ++i) o[i] = (1.0 - s) * a[i] + s * b[i];
  }
}

bool refuse(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

bool positive_finite(double x) { return x > 0.0 && std::isfinite(x); }
bool zero_or_positive_finite(double x) { return x >= 0.0 && std::isfinite(x); }

}  // namespace

bool IntegratorOptions::IsValid(std::string* error) const {
  const std::string name = method_name(method);
  if (!method_from_name(name)) return refuse(error, "unknown integrator method");
  if (!positive_finite(rtol)) return refuse(error, "rtol must be positive and finite");
  if (!positive_finite(atol)) return refuse(error, "atol must be positive and finite");
  const bool cvode = method == IntegratorMethod::kBdf || method == IntegratorMethod::kAdams;
  const int limit = method == IntegratorMethod::kAdams ? 12 : 5;
  if (cvode && (max_order < 1 || max_order > limit))
    return refuse(error, name + " orders go from 1 to " + std::to_string(limit));
  if (!table.empty() && method != IntegratorMethod::kDirk && method != IntegratorMethod::kErk)
    return refuse(error, "a Butcher table applies to the \"dirk\" and \"erk\" methods");
  if (stability_limit_detection && method != IntegratorMethod::kBdf)
    return refuse(error, "stability_limit_detection applies to the \"bdf\" method");
  if (jacobian == JacobianKind::kFiniteDifference && linear_solver == LinearSolverKind::kSparse)
    return refuse(error, "finite-difference Jacobians need the dense linear solver");
  if (!zero_or_positive_finite(max_step))
    return refuse(error, "max_step must be 0 (no limit) or positive and finite");
  if (!zero_or_positive_finite(initial_step))
    return refuse(error, "initial_step must be 0 (the integrator's estimate) or positive");
  if (!zero_or_positive_finite(fixed_step))
    return refuse(error, "fixed_step must be 0 (adaptive steps) or positive and finite");
  if (fixed_step > 0.0 && method != IntegratorMethod::kDirk && method != IntegratorMethod::kErk)
    return refuse(error, "fixed_step applies to the \"dirk\" and \"erk\" methods");
  if (fixed_step > 0.0 && (max_step > 0.0 || initial_step > 0.0))
    return refuse(error, "fixed_step sets every step: max_step and initial_step do not apply");
  if (max_steps < 1) return refuse(error, "max_steps must be at least 1");
  if (!about.empty() && about != "static" && about != "initial")
    return refuse(error, "about must be \"static\", \"initial\" or empty");
  const bool modal = method == IntegratorMethod::kModal || method == IntegratorMethod::kAuto;
  if (!about.empty() && !modal)
    return refuse(error, "about applies to the \"modal\" and \"auto\" methods");
  if (!zero_or_positive_finite(max_frequency_hz))
    return refuse(error, "max_frequency_hz must be 0 (every mode) or positive and finite");
  if (max_frequency_hz > 0.0 && !modal)
    return refuse(error, "max_frequency_hz applies to the \"modal\" and \"auto\" methods");
  if (choose_band && max_frequency_hz > 0.0)
    return refuse(error,
                  "max_frequency_hz is either a frequency or chosen (choose_band), not both");
  if (choose_band && !modal)
    return refuse(error, "choose_band applies to the \"modal\" and \"auto\" methods");
  if (!zero_or_positive_finite(max_rotation))
    return refuse(error, "max_rotation must be 0 (the modal limit) or positive and finite");
  return true;
}

bool TransientOptions::IsValid(std::string* error) const {
  if (!positive_finite(t_end)) return refuse(error, "t_end must be positive and finite");
  if (!positive_finite(output_step))
    return refuse(error, "output_step must be positive and finite");
  // An output step beyond t_end is one step, to t_end.
  if (t_end / output_step > 1e8) return refuse(error, "more than 1e8 output rows requested");
  if (!zero_or_positive_finite(max_seconds))
    return refuse(error, "max_seconds must be 0 (no budget) or positive and finite");
  if (!integrator.IsValid(error)) return false;
  // A fixed step longer than the run is one step with no error estimate; one so short that the
  // run would take more than max_steps steps fails only after all of them (1e-300 s: minutes).
  const double h = integrator.fixed_step;
  if (h > t_end) return refuse(error, "fixed_step must not exceed t_end");
  if (h > 0.0 && t_end / h > static_cast<double>(integrator.max_steps)) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "fixed_step %g s takes %.3g steps over t_end, more than max_steps (%ld)", h,
                  t_end / h, integrator.max_steps);
    return refuse(error, text);
  }
  return true;
}

TransientResult run_transient(const Model& model, const TransientOptions& options, Data& data,
                              const TransientObserver& observer) {
  TransientResult result;
  const auto start = std::chrono::steady_clock::now();
  if (!options.IsValid(&result.message)) {
    result.message = "invalid transient options: " + result.message;
    return result;
  }
  IntegratorOptions io = options.integrator;
  io.horizon = options.t_end;
  // The longest step that still samples every harmonic load and drive: 1 / (2 pi f) for the
  // highest frequency f among them [s]; 0 without one. A step's stages see a time function only
  // at their own times, and neither the error estimates nor the step count see what happens in
  // between: a 100 Hz load on a cantilever with outputs every 0.01 s, one step per output, sampled
  // the sine at its zeros only (stages at 0, h/2 and h) and the run came out at rest, with status
  // ok (an adversarial review, 2026-11-29: every method and rtol; bdf 6.6 and dirk 95 rtol off at
  // rtol 1e-6 with longer steps). The bound keeps about six steps per period: at 1 / (2 pi f) that
  // run was 9.6 / 24 / 40 rtol off at rtol 1e-4 / 1e-6 / 1e-8, not 1e4 / 1e6 / 1e8.
  const double highest_hz = highest_harmonic_hz(model);
  const double harmonic_step = highest_hz > 0.0 ? 1.0 / (2.0 * std::numbers::pi * highest_hz) : 0.0;
  const bool harmonic_held = harmonic_step > 0.0 && !(io.fixed_step > 0.0) &&
                             !(io.max_step > 0.0 && io.max_step <= harmonic_step);
  if (harmonic_held) io.max_step = harmonic_step;
  if (harmonic_held && options.t_end / harmonic_step > static_cast<double>(io.max_steps)) {
    // Known before the run: it would spend every step of its budget and fail.
    char text[400];
    std::snprintf(text, sizeof text,
                  "its harmonic loads or drives (%.6g Hz, the highest) hold every step to at most "
                  "%.3g s, 1 / (2 pi f): t_end needs at least %.3g steps, more than max_steps "
                  "(%ld); raise max_steps or shorten t_end",
                  highest_hz, harmonic_step, options.t_end / harmonic_step, io.max_steps);
    result.message = text;
    return result;
  }
  DeformationCheck deformation(model);
  try {
    SundialsContext ctx;
    OdeContext context(model, data);
    context.structure_cache = options.structure_cache;
    context.cancel = options.cancel;
    if (options.max_seconds > 0.0)
      context.deadline = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                     std::chrono::duration<double>(options.max_seconds));
    const long n = model.n_states;
    SerialVector y(n, ctx);
    if (options.initial_state.empty())
      initial_state(model, y.data());
    else if (static_cast<long>(options.initial_state.size()) == n)
      std::copy(options.initial_state.begin(), options.initial_state.end(), y.data());
    else
      throw std::invalid_argument("the initial state has " +
                                  std::to_string(options.initial_state.size()) +
                                  " entries; the model has " + std::to_string(n) + " states");
    std::string error;
    const std::unique_ptr<Integrator> integrator = make_integrator(io, context, ctx, y, &error);
    if (!integrator) {
      result.message = error;
      result.timed_out = context.timed_out;
      result.stats.wall_seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      return result;
    }
    integrator->phase_started = options.phase_started;
    result.linear_solver = integrator->linear_solver;
    const std::vector<std::string> set_up_warnings = integrator->warnings;
    result.warnings = set_up_warnings;
    if (harmonic_step > 0.0 && io.fixed_step > harmonic_step) {
      char text[400];
      std::snprintf(text, sizeof text,
                    "fixed_step %.3g s is longer than 1 / (2 pi f) = %.3g s for its harmonic loads "
                    "or drives (%.6g Hz, the highest): each period is sampled fewer than 2 pi "
                    "times, and nothing estimates what the load does between the samples",
                    io.fixed_step, harmonic_step, highest_hz);
      result.warnings.push_back(text);
    }
    result.jacobian_nonzeros = integrator->nnz;

    const long n_out =
        std::max(1L, static_cast<long>(std::ceil(options.t_end / options.output_step - 1e-9)));
    AxialForceWatch axial(model, options.structure_cache, n_out);
    // The small-angle and rail-travel warnings watch every accepted step, not only the rows: a
    // swing to 0.8 rad and back between two rows was once not warned of by any method.
    Data watched(model);
    // And the path between two accepted steps (state_between at the points of kPathSamples; the
    // modal method bounds its own: OdeContext::path_bounded): a
    // carriage thrown against a constant force, 1 to 5 mm past its travel's end and back between
    // two of bdf's steps, was ok at rtol 1e-4 .. 1e-8 (its rerun at rtol / 10 too), and a dip
    // below a rail's min_length went unwarned (an adversarial review, 2026-12-02). An element
    // outside its law's range there by more than kPathTolerances times its tolerance
    // (path_outside) ends the run, through context.divergence, which every method's next
    // evaluation honours; nearer, the interpolated path is as uncertain as that (bdf at rtol 1e-4
    // put a swing that stays 10 um inside its travel 0.2 mm outside).
    std::vector<double> last_y(y.data(), y.data() + n), between(n);
    // Where the path was found to leave an element's range (path_exit) [s].
    double path_exit_t = std::numeric_limits<double>::infinity();
    double last_t = 0.0;
    const auto path_outside = [&](const ElementMargins& m) {
      const double rtol = options.integrator.rtol, atol = options.integrator.atol;
      for (size_t e = 0; e < m.length.size(); ++e) {
        const double scale = e < model.beams.size()
                                 ? model.beams[e].ends.length
                                 : model.rails[e - model.beams.size()].ends.length;
        if (-m.length[e] > kPathTolerances * (rtol * scale + atol) ||
            -m.angle[e] > kPathTolerances * (rtol + atol))
          return true;
      }
      return false;
    };
    double arm = 0.0;  // the longest centre -> attachment arm of an element [m]
    double last_length = 0.0, last_angle = 0.0;  // the smallest margins at the last step
    // Whether they are: a step whose method bounds its own path (the modal method) leaves them
    // to be found at last_y when a step that does not follows (auto's hand-over).
    bool last_margins = true;
    const auto smallest_margins = [&](const double* y_at, double t_at, double* length,
                                      double* angle) {
      set_state(model, watched, y_at);
      set_driven_poses(model, watched, t_at);
      const ElementMargins m = element_margins(model, watched);
      *length = *std::min_element(m.length.begin(), m.length.end());
      *angle = *std::min_element(m.angle.begin(), m.angle.end());
    };
    {
      set_state(model, watched, y.data());
      set_driven_poses(model, watched, 0.0);
      const ElementMargins start = element_margins(model, watched);
      if (!start.length.empty()) {
        last_length = *std::min_element(start.length.begin(), start.length.end());
        last_angle = *std::min_element(start.angle.begin(), start.angle.end());
      }
      const auto lever = [&](const ElementEnds& ends, RotationMeasure measure) {
        const ElementFrames<double> f =
            element_frames(ends, watched.pose[ends.body1], watched.pose[ends.body2], measure);
        arm = std::max({arm, f.R1.norm(), f.R2.norm()});
      };
      for (const Beam& e : model.beams) lever(e.ends, rotation_measure(e));
      for (const Rail& e : model.rails) lever(e.ends, rotation_measure(e));
    }
    context.step_taken = [&](double t_step, const double* y_step) {
      // CVODE shows the same state at each attempt of a step: looked at once.
      const bool elements = !(model.beams.empty() && model.rails.empty()) && t_step > last_t;
      double end_length = last_length, end_angle = last_angle;  // the smallest margins here
      if (elements && !context.path_bounded) {
        if (!last_margins) {
          smallest_margins(last_y.data(), last_t, &last_length, &last_angle);
          last_margins = true;
        }
        smallest_margins(y_step, t_step, &end_length, &end_angle);
      }
      if (t_step > last_t && context.divergence.empty() && !context.path_bounded && elements) {
        const double h = t_step - last_t;
        const auto [a_length, a_angle] = path_accelerations(model, h, last_y.data(), y_step, arm);
        double length = std::min(last_length, end_length);
        double angle = std::min(last_angle, end_angle);
        // Where the path first leaves an element's range before the sample s_out found outside
        // (as a fraction of the step): the first of kPathExitScan even points up to s_out that is
        // outside, bisected against the one before it (to kPathExitBisections halvings). The
        // samples alone named a time up to 19 ms late (bdf at rtol 1e-4: 0.097 s for an exit at
        // 0.0859 s in a step from 0.073 to 0.168 s).
        const auto path_exit = [&](double s_out) {
          const auto outside = [&](double s) {
            state_between(model, last_t, last_y.data(), t_step, y_step, s, between.data());
            set_state(model, watched, between.data());
            set_driven_poses(model, watched, last_t + s * h);
            return !element_out_of_range(model, watched).empty();
          };
          double lo = 0.0, hi = s_out;
          for (int j = 1; j < kPathExitScan; ++j) {
            const double s = s_out * j / kPathExitScan;
            if (outside(s)) {
              hi = s;
              break;
            }
            lo = s;
          }
          for (int i = 0; i < kPathExitBisections; ++i) {
            const double mid = 0.5 * (lo + hi);
            (outside(mid) ? hi : lo) = mid;
          }
          return hi;
        };
        // Looks at the sample s of the step: false when an element is outside there.
        const auto look = [&](double s) {
          const double t_s = last_t + s * h;
          state_between(model, last_t, last_y.data(), t_step, y_step, s, between.data());
          set_state(model, watched, between.data());
          set_driven_poses(model, watched, t_s);
          deformation.observe(model, watched, t_s);
          for (size_t r = 0; r < model.rails.size(); ++r) {  // a dip below min_length, too
            const Rail& e = model.rails[r];
            if (e.min_length > 0.0 &&
                std::abs(element_frames(e.ends, watched.pose[e.ends.body1],
                                        watched.pose[e.ends.body2], rotation_measure(e))
                             .xi(0)) < e.min_length)
              data.rail_floored_ever[r] = 1;
          }
          const ElementMargins m = element_margins(model, watched);
          length = std::min(length, *std::min_element(m.length.begin(), m.length.end()));
          angle = std::min(angle, *std::min_element(m.angle.begin(), m.angle.end()));
          if (std::string range = element_out_of_range(model, watched);
              !range.empty() && path_outside(m)) {
            const double t_exit = last_t + path_exit(s) * h;
            char when[200];
            std::snprintf(when, sizeof when,
                          "at t = %.9g s (on the path between the steps at %.9g and %.9g s; at "
                          "t = %.9g s), ",
                          t_exit, last_t, t_step, t_s);
            context.out_of_range = when + range;
            context.out_of_range_t = t_exit;
            path_exit_t = t_exit;
            context.divergence = context.out_of_range;
            return false;
          }
          return true;
        };
        // The path leaves the chord between the two ends by at most a h^2 / 8: where that is
        // below kPathShare of their margins no sample can be outside or warned (the braced tower
        // under bdf: every step; looked at, its run took twice as long).
        const double chord = h * h / 8.0;
        bool looking = !((length > 0.0 && a_length * chord <= kPathShare * length) &&
                         (angle > 0.0 && a_angle * chord <= kPathShare * angle));
        for (int parts = kPathSamples; looking; parts *= 2) {
          // The new samples: all at first, then the odd ones (the even ones were looked at).
          for (int k = 1; k < parts && looking; k += parts == kPathSamples ? 1 : 2)
            looking = look(static_cast<double>(k) / parts);
          const double unseen = (h / parts) * (h / parts) / 8.0;
          if (parts >= kMostPathSamples ||
              ((!(length > 0.0) || a_length * unseen <= kPathShare * length) &&
               (!(angle > 0.0) || a_angle * unseen <= kPathShare * angle)))
            break;
        }
      }
      if (t_step >= last_t) {
        std::copy(y_step, y_step + n, last_y.begin());
        last_t = t_step;
        last_length = end_length;
        last_angle = end_angle;
        if (elements) last_margins = !context.path_bounded;
      }
      set_state(model, watched, y_step);
      set_driven_poses(model, watched, t_step);
      deformation.observe(model, watched, t_step);
    };
    const auto deliver = [&](long k, double t) {
      const TransientSample s = sample_at(model, data, t, y.data());
      deformation.observe(model, data, t);
      axial.observe(model, data, k, t);
      if (observer) observer(s, data);
    };
    deliver(0, 0.0);

    const std::vector<Stop> breakpoints = time_breakpoints(model, options.t_end);
    size_t next_break = 0;
    double t = 0.0;
    result.ok = true;
    // Times closer than this are one time: an output time and a breakpoint computed apart (110 x
    // 1e-4 = 0.011000000000000001 against a table's knot at 0.011) once asked every method for a
    // step of 1.7e-18 s, which each refused ("tout too close to t0").
    const double same_time = 1e-9 * std::min(options.output_step, options.t_end);
    for (long k = 1; k <= n_out && result.ok; ++k) {
      const double t_out = std::min(static_cast<double>(k) * options.output_step, options.t_end);
      while (t_out - t > same_time) {
        // Never step across a load's jump: stop there and restart the method (at a smooth
        // ramp's end: stop, and go on).
        const bool at_break = next_break < breakpoints.size();
        const double stop = at_break ? breakpoints[next_break].t : options.t_end;
        const auto pass = [&] {
          if (!breakpoints[next_break++].restart) return;
          context.stretch_start = stop;
          normalize_quaternions(model, y.data());
          integrator->restart(t, y);
        };
        if (at_break && stop - t <= same_time) {  // there already
          pass();
          continue;
        }
        // A jump at the stretch's end (or at t_end) acts after it: the forces there are its left
        // limit.
        context.stretch_end = stop;
        const int flag = integrator->advance(std::min(t_out, stop), stop, y, &t);
        if (flag < 0) {
          t = std::min(t, path_exit_t);
          result.ok = false;
          result.timed_out = context.timed_out;
          result.interrupted = context.interrupted;
          result.message = context.interrupted ? "interrupted" : integrator->failure(flag);
          result.out_of_range = !context.out_of_range.empty() &&
                                result.message.find(context.out_of_range) != std::string::npos;
          if (harmonic_held && result.message.find("max_steps") != std::string::npos) {
            char why[160];
            std::snprintf(why, sizeof why,
                          "; with its harmonic loads or drives no step is longer than %.3g s, "
                          "1 / (2 pi f) for the highest frequency f (%.6g Hz)",
                          harmonic_step, highest_hz);
            result.message += why;
          }
          break;
        }
        // CVODE shows a step's state to step_taken only as the next step begins: the last step
        // to an output (or to t_end, with no step after it) is looked at here.
        if (t > last_t && !context.path_bounded) context.step_taken(t, y.data());
        if (!context.divergence.empty()) {  // outside on the path between two steps
          result.ok = false;
          result.message = context.divergence;
          result.out_of_range = true;
          t = std::min(t, path_exit_t);  // the run reached the exit, not beyond
          break;
        }
        if (at_break && t >= stop) pass();
      }
      if (result.ok) deliver(k, t_out);
      // An element outside the range of its law ends the run (checked at accepted states).
      if (std::string range = element_out_of_range(model, data); result.ok && !range.empty()) {
        result.ok = false;
        result.out_of_range = true;
        char when[64];
        std::snprintf(when, sizeof when, "at t = %.6g s, ", t_out);
        result.message = when + range;
      }
    }
    // The last output time when every one was delivered (t may lie within same_time of it).
    result.t_reached = result.ok ? options.t_end : t;
    result.stats = integrator->stats();
    result.phases = integrator->phases(&result.phase_count);
    result.max_frequency_hz = integrator->band_hz;
    for (const std::string& w : integrator->warnings)  // auto's arrive during the run
      if (std::find(result.warnings.begin(), result.warnings.end(), w) == result.warnings.end())
        result.warnings.push_back(w);
    // and auto withdraws those of a first modal phase that failed before its first step.
    const std::vector<std::string>& kept = integrator->warnings;
    for (const std::string& w : set_up_warnings)
      if (std::find(kept.begin(), kept.end(), w) == kept.end())
        result.warnings.erase(std::remove(result.warnings.begin(), result.warnings.end(), w),
                              result.warnings.end());
    for (std::string& w : integrator->closing_warnings()) result.warnings.push_back(std::move(w));
    result.axial_force_effect = axial.largest();
    result.axial_force_time = axial.when();
    result.axial_force_states = axial.measured();
    result.axial_force_seconds = axial.seconds();
    result.axial_force_unmeasured = axial.unmeasured();
    for (std::string w : {axial.warning(), axial.unmeasured_warning()})
      if (!w.empty()) result.warnings.push_back(std::move(w));
  } catch (const std::exception& e) {
    result.ok = false;
    result.message = e.what();
  }
  for (size_t r = 0; r < model.rails.size(); ++r)
    if (data.rail_floored_ever[r])
      result.warnings.push_back("rail \"" + model.rails[r].name + "\" reached its min_length");
  // Checked at the accepted steps and the output samples, never at trial states.
  for (std::string& w : deformation.warnings(model, true)) result.warnings.push_back(std::move(w));
  result.stats.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace beamrail
