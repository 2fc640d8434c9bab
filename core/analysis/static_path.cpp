// Arc-length control of the static analysis (docs/model.md "Arc-length control"): the load factor
// lambda is an unknown, and each step moves a given distance ds along the load-displacement path,
//   R(x, lambda) = 0,   |Dx|^2 = ds^2        (the cylindrical arc length of Crisfield: the
//                                             displacement part only; rotations count times the
//                                             structure's characteristic length),
// where Dx is the step's displacement. Each corrector iteration solves the tangent S = dR/dx twice,
// S dx_R = -R and S dx_F = -F (F = dR/dlambda, the loads at the current pose: a follower load
// turns with its body), and takes dlambda from the constraint, a quadratic in dlambda, choosing the
// root that keeps the step's direction. The predictor follows dx_F in the direction of the last
// step (its sign by the dot product with it), so the path passes limit points, where the load
// factor turns back, and snaps through. A step that does not converge is retried at half the
// length; lengths adapt to the iterations taken.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/analysis/static_newton.hpp"

namespace beamrail::statics {
namespace {

// Corrector iterations a step aims at: the next step's length scales by sqrt(this / taken).
constexpr double kTargetIterations = 4.0;
// A step that fails this many halvings in a row ends the path.
constexpr int kMaxHalvings = 20;
// Once the path has passed its first maximum of the load factor, it walks the last two steps
// again with steps this many times shorter, so that the parabola through the highest points
// locates the limit load: the interpolation error falls with the steps' length cubed (Lee's frame
// in 160 segments: 3e-4 of the limit load at the adapted steps, below 1e-6 walked again).
constexpr double kLimitRefinement = 10.0;
// The path records at most this many bodies (its memory: 48 bytes per body and point).
constexpr size_t kMaxPathBodies = 1000;

// F = dR/dlambda at the current pose: the loads and gravity at full value (the wrench at load
// factor 1 minus that at 0: the element forces cancel).
Eigen::VectorXd load_vector(Newton& n) {
  compute_wrenches(n.model, n.data, n.t, 1.0);
  const Eigen::VectorXd full = wrench_vector(n.model, n.data);
  compute_wrenches(n.model, n.data, n.t, 0.0);
  return full - wrench_vector(n.model, n.data);
}

// The dot product of the arc length: rotations times the characteristic length.
double path_dot(const Eigen::VectorXd& a, const Eigen::VectorXd& b, double length) {
  double sum = 0.0;
  for (Eigen::Index i = 0; i < a.size(); ++i)
    sum += a(i) * b(i) * ((i % kDofsPerBody) < 3 ? 1.0 : length * length);
  return sum;
}

// The largest rotation of a body in an increment.
double largest_turn(const Eigen::VectorXd& dx) {
  double turn = 0.0;
  for (Eigen::Index k = 0; k + kDofsPerBody <= dx.size(); k += kDofsPerBody)
    turn = std::max(turn, dx.segment<3>(k + 3).norm());
  return turn;
}

StaticPathPoint path_point(const Newton& n, const std::vector<int>& bodies, double lambda, double s,
                           int iterations) {
  StaticPathPoint p;
  p.load_factor = lambda;
  p.arc_length = s;
  p.iterations = iterations;
  for (int i : bodies) {
    p.displacement.push_back(n.data.pose[i].u);
    p.rotation.push_back(n.data.rotation[i]);
  }
  return p;
}

// The first maximum of the load factor along the path: the vertex of the parabola in the arc
// length through the highest point and its neighbours.
double first_limit(const std::vector<StaticPathPoint>& path) {
  for (size_t k = 1; k + 1 < path.size(); ++k) {
    const StaticPathPoint &a = path[k - 1], &b = path[k], &c = path[k + 1];
    if (!(b.load_factor > a.load_factor && b.load_factor >= c.load_factor)) continue;
    const double h1 = b.arc_length - a.arc_length, h2 = c.arc_length - b.arc_length;
    const double d1 = (b.load_factor - a.load_factor) / h1;
    const double d2 = (c.load_factor - b.load_factor) / h2;
    const double curvature =
        (d2 - d1) / (h1 + h2);  // lambda = b + slope (s - sb) + curv (s - sb)^2
    const double slope = d1 + curvature * h1;
    if (!(curvature < 0.0)) return b.load_factor;
    return b.load_factor - slope * slope / (4.0 * curvature);
  }
  return std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

bool follow_path(Newton& n, const StaticOptions& options, double f_ref, StaticResult& result,
                 double* done) {
  const Model& model = n.model;
  Data& data = n.data;
  const double length = n.length;
  for (int k = 0; k < model.n_free(); ++k)
    if (!model.bodies[model.free_bodies[k]].generated)
      result.path_bodies.push_back(model.free_bodies[k]);
  if (result.path_bodies.empty()) result.path_bodies = model.free_bodies;
  if (result.path_bodies.size() > kMaxPathBodies) {
    result.warnings.push_back("the load path records the first " + std::to_string(kMaxPathBodies) +
                              " of the scene's " + std::to_string(result.path_bodies.size()) +
                              " free bodies");
    result.path_bodies.resize(kMaxPathBodies);
  }
  double lambda = 0.0, s = 0.0;
  const auto finish = [&](bool ok, const std::string& message) {
    result.limit_load_factor = first_limit(result.path);
    if (!ok && lambda < 1.0) *done = lambda;  // the state is the last point's
    if (!ok) result.message = message;
    if (!ok && !std::isnan(result.limit_load_factor))
      result.message +=
          format("; the path passed a limit point at load factor %.6g", result.limit_load_factor);
    return ok;
  };
  const double target = options.tolerance * f_ref;
  n.solver.keep_near_singular = true;
  std::string why;
  // The first step: a tenth of the linear response to the full loads, unless given.
  compute_tangent(model, data, n.t, false, 0.0);
  if (!n.solver.factorize(model, data, &why)) return finish(false, why + " (at the start)");
  // A mechanism (a carriage free along its rails) has no path to follow: load control solves it
  // minimum-norm, with a warning, or finds no equilibrium.
  if (n.solver.null_directions > 0)
    return finish(false, "the tangent stiffness at the start has " +
                             std::to_string(n.solver.null_directions) +
                             " direction(s) without stiffness (a free mechanism): arc-length "
                             "control needs a structure that carries the loads at first; use "
                             "\"control\": \"load\"");
  Eigen::VectorXd dx_f = n.solver.solve(-load_vector(n));
  if (!dx_f.allFinite() || !(motion_size(dx_f, length) > 0.0))
    return finish(false,
                  "the tangent stiffness at the start is singular: arc-length control "
                  "needs a structure that carries the loads at first");
  // The steps are at most this long (they shorten where the path turns or Newton struggles).
  const double ds_max =
      options.arc_length > 0.0 ? options.arc_length : 0.1 * motion_size(dx_f, length);
  double ds = ds_max;
  const double ds_min = ds_max * std::ldexp(1.0, -kMaxHalvings);
  Eigen::VectorXd previous;  // the last step's displacement
  int halvings = 0;
  result.path.push_back(path_point(n, result.path_bodies, 0.0, 0.0, 0));
  // The last two points, to walk the first maximum of the load factor again (kLimitRefinement).
  struct Mark {
    Newton::Saved state;
    double lambda = 0.0, s = 0.0;
    Eigen::VectorXd previous;
  };
  Mark last{n.save(), 0.0, 0.0, {}}, before_last = last;
  enum class Limit { kAhead, kRefining, kPassed } limit = Limit::kAhead;
  double ds_cap = ds_max;
  while (true) {
    if (result.load_steps >= options.max_load_steps)
      return finish(false, "the load path took " + std::to_string(options.max_load_steps) +
                               format(" steps without reaching the full loads (load factor %.6g "
                                      "at the last point)",
                                      lambda));
    if (n.budget.passed())
      return finish(false, "the static analysis did not finish within its time budget");
    ++result.load_steps;
    const Newton::Saved saved = n.save();
    const Eigen::VectorXd start = displacement(model, data);
    // Predictor: along dx_F at the last point, in the direction of the last step.
    compute_tangent(model, data, n.t, false, lambda);
    ++n.iterations;
    bool ok = n.solver.factorize(model, data, &why);
    if (ok) {
      dx_f = n.solver.solve(-load_vector(n));
      ok = dx_f.allFinite() && motion_size(dx_f, length) > 0.0;
    }
    Eigen::VectorXd dx;
    double dlambda = 0.0, step = ds;
    int iterations = 0;
    if (ok) {
      const double sign = previous.size() && path_dot(dx_f, previous, length) < 0.0 ? -1.0 : 1.0;
      dlambda = sign * ds / motion_size(dx_f, length);
      dx = dlambda * dx_f;
      if (const double turn = largest_turn(dx); turn > kMaxRotationStep) {
        dx *= kMaxRotationStep / turn;
        dlambda *= kMaxRotationStep / turn;
        step = motion_size(dx, length);
      }
      apply_increment(model, data, dx);
      ok = false;
      for (; iterations <= options.max_iterations; ++iterations) {
        compute_wrenches(model, data, n.t, lambda + dlambda);
        const Eigen::VectorXd w = wrench_vector(model, data);
        const double r = scaled_norm(w, length);
        if (!std::isfinite(r)) break;
        const double floor = n.solver.rounding_floor(displacement(model, data), length);
        if (iterations > 0 && r <= std::max(target, 10.0 * floor)) {
          ok = true;
          break;
        }
        if (iterations == options.max_iterations) break;
        compute_tangent(model, data, n.t, false, lambda + dlambda);
        ++n.iterations;
        if (!n.solver.factorize(model, data, &why)) break;
        const Eigen::VectorXd dx_r = n.solver.solve(-w);
        dx_f = n.solver.solve(-load_vector(n));
        if (!dx_r.allFinite() || !dx_f.allFinite()) break;
        // |dx + dx_R + q dx_F|^2 = step^2, a q^2 + b q + c = 0.
        const Eigen::VectorXd base = dx + dx_r;
        const double a = path_dot(dx_f, dx_f, length);
        const double b = 2.0 * path_dot(dx_f, base, length);
        const double c = path_dot(base, base, length) - step * step;
        const double disc = b * b - 4.0 * a * c;
        if (!(a > 0.0) || !(disc >= 0.0)) break;  // the constraint missed: a shorter step
        const double root = std::sqrt(disc);
        const double q1 = (-b + root) / (2.0 * a), q2 = (-b - root) / (2.0 * a);
        // The root that keeps the direction of the step so far.
        const double q =
            path_dot(base + q1 * dx_f, dx, length) >= path_dot(base + q2 * dx_f, dx, length) ? q1
                                                                                             : q2;
        Eigen::VectorXd delta = dx_r + q * dx_f;
        double dq = q;
        if (const double turn = largest_turn(delta); turn > kMaxRotationStep) {
          delta *= kMaxRotationStep / turn;
          dq *= kMaxRotationStep / turn;
        }
        apply_increment(model, data, delta);
        dx += delta;
        dlambda += dq;
        if (!element_turned_beyond(model, data, kIterateRotationLimit).empty()) break;
      }
    }
    if (!ok) {
      n.restore(saved);
      ds *= 0.5;
      if (++halvings > kMaxHalvings || ds < ds_min)
        return finish(false, format("the load path could not be continued beyond load factor "
                                    "%.6g (steps down to %.3g m did not converge)",
                                    lambda, ds) +
                                 (why.empty() ? "" : ": " + why));
      continue;
    }
    halvings = 0;
    const double before = lambda;
    lambda += dlambda;
    s += step;
    previous = dx;
    result.path.push_back(path_point(n, result.path_bodies, lambda, s, iterations));
    ds = std::min(ds_cap, step * std::clamp(std::sqrt(kTargetIterations / std::max(iterations, 1)),
                                            0.5, 2.0));
    if (lambda >= 1.0 && before < 1.0) {
      // The full loads lie on this step: their equilibrium by Newton from its end.
      // With the checks of load control (a nearly singular tangent solved minimum-norm and
      // judged: the equilibrium must not lean on a direction without stiffness).
      n.solver.keep_near_singular = false;
      n.failure.clear();
      const int before_newton = n.iterations;
      if (!n.solve(1.0, target)) {
        *done = lambda;
        return finish(
            false, "the load path reached the full loads, but Newton at them failed: " + n.failure);
      }
      // Its arc length: from the step's start.
      const double s_full = s - step + motion_size(displacement(model, data) - start, length);
      result.path.pop_back();  // the step's end: past the full loads
      result.path.push_back(
          path_point(n, result.path_bodies, 1.0, s_full, n.iterations - before_newton));
      *done = 1.0;
      return finish(true, "");
    }
    const size_t m = result.path.size();
    const bool turned_down = m >= 3 &&
                             result.path[m - 2].load_factor > result.path[m - 3].load_factor &&
                             result.path[m - 1].load_factor < result.path[m - 2].load_factor;
    if (turned_down && limit == Limit::kAhead) {
      // Back to the point before the highest, and over the maximum again in short steps.
      limit = Limit::kRefining;
      ds_cap = (result.path[m - 1].arc_length - result.path[m - 3].arc_length) / kLimitRefinement;
      ds = ds_cap;
      n.restore(before_last.state);
      lambda = before_last.lambda;
      s = before_last.s;
      previous = before_last.previous;
      result.path.resize(m - 2);
      last = before_last;
      continue;
    }
    if (turned_down && limit == Limit::kRefining) {
      limit = Limit::kPassed;
      ds_cap = ds_max;
    }
    before_last = std::move(last);
    last = Mark{n.save(), lambda, s, previous};
  }
}

}  // namespace beamrail::statics
