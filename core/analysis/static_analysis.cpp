#include "core/analysis/static_analysis.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseLU>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"

namespace beamrail {
namespace {

// Largest element length, the length that turns moments into forces in the residual norm.
double characteristic_length(const Model& model) {
  double l = 0.0;
  for (const Beam& e : model.beams) l = std::max(l, e.ends.length);
  for (const Rail& e : model.rails) l = std::max(l, e.ends.length);
  return l > 0.0 ? l : 1.0;
}

// The load scale: the largest applied force (moments / length) or weight, at full load.
double reference_force(const Model& model, double t, double length) {
  double f = 0.0;
  for (int i : model.free_bodies) f = std::max(f, model.bodies[i].mass * model.gravity.norm());
  for (const Load& load : model.loads) {
    const double v = std::abs(load.time(t)) * load.value.norm();
    f = std::max(f, load.kind == LoadKind::kForce ? v : v / length);
  }
  return f;
}

double scaled_norm(const Eigen::VectorXd& w, double length) {
  double n = 0.0;
  for (Eigen::Index i = 0; i < w.size(); ++i)
    n = std::max(n, std::abs(w(i)) / ((i % kDofsPerBody) < 3 ? 1.0 : length));
  return n;
}

struct Newton {
  const Model& model;
  Data& data;
  double t, length, tolerance;
  int max_iterations;
  int iterations = 0;
  int singular = 0;
  double residual = 0.0;
  std::string failure;

  double residual_at(double factor) {
    compute_wrenches(model, data, t, factor);
    return scaled_norm(wrench_vector(model, data), length);
  }

  // Solves S dx = -w; falls back to the minimum-norm solution when S is singular.
  bool step(const Eigen::SparseMatrix<double>& s, const Eigen::VectorXd& w, Eigen::VectorXd& dx) {
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
    lu.compute(s);
    if (lu.info() == Eigen::Success) {
      dx = lu.solve(-w);
      if (dx.allFinite() && (s * dx + w).norm() <= 1e-8 * (w.norm() + 1e-300)) return true;
    }
    if (model.n_dofs > 3000) {
      failure = "the tangent stiffness is singular (a body or mechanism is free to move)";
      return false;
    }
    const Eigen::MatrixXd dense(s);
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(dense);
    cod.setThreshold(1e-12);
    singular = std::max(singular, static_cast<int>(dense.rows() - cod.rank()));
    dx = cod.solve(-w);
    if (!dx.allFinite()) {
      failure = "the tangent stiffness is singular";
      return false;
    }
    return true;
  }

  // Newton iterations at load factor `factor` from the current state; true when converged.
  bool solve(double factor, double target) {
    double r = residual_at(factor);
    for (int it = 0; it < max_iterations; ++it) {
      if (r <= target) {
        residual = r;
        return true;
      }
      compute_tangent(model, data, t, false, factor);
      const Eigen::VectorXd w = wrench_vector(model, data);
      Eigen::VectorXd dx;
      ++iterations;
      if (!step(stiffness_matrix(model, data), w, dx)) return false;
      // Backtracking: accept the first fraction that reduces the residual.
      const std::vector<Pose<double>> pose = data.pose;
      const std::vector<Vec4> q = data.q;
      double fraction = 1.0, trial = 0.0;
      for (int k = 0; k < 12; ++k) {
        apply_increment(model, data, fraction * dx);
        trial = residual_at(factor);
        if (std::isfinite(trial) && trial <= (1.0 - 1e-4 * fraction) * r) break;
        data.pose = pose;
        data.q = q;
        fraction *= 0.5;
        trial = std::numeric_limits<double>::infinity();
      }
      if (!std::isfinite(trial)) {
        // No descent: converged to rounding if the step is negligible, else stuck.
        const double size = scaled_norm(dx, 1.0 / length);
        if (size <= 1e-13 * length) {
          residual = r;
          return r <= 1e3 * target;
        }
        failure = "the line search found no decrease of the residual";
        return false;
      }
      r = trial;
    }
    residual = r;
    if (r <= target) return true;
    failure = "Newton did not converge in " + std::to_string(max_iterations) + " iterations";
    return false;
  }
};

}  // namespace

StaticResult solve_static(const Model& model, const StaticOptions& options, Data& data) {
  const auto start = std::chrono::steady_clock::now();
  StaticResult result;
  try {
    reset_to_initial(model, data);
    const double length = characteristic_length(model);
    const double f_ref = reference_force(model, options.time, length);
    result.reference_force = f_ref;
    Newton newton{model, data, options.time, length, options.tolerance, options.max_iterations,
                  0,     0,    0.0,          {}};
    const double target = options.tolerance * f_ref;

    double done = 0.0;  // load factor reached
    double increment = options.load_steps > 0 ? 1.0 / options.load_steps : 1.0;
    const double min_increment = 1.0 / (1 << 20);
    while (done < 1.0) {
      if (result.load_steps >= options.max_load_steps) {
        result.message = "more than " + std::to_string(options.max_load_steps) + " load steps";
        break;
      }
      const double factor = std::min(1.0, done + increment);
      const std::vector<Pose<double>> pose = data.pose;
      const std::vector<Vec4> q = data.q;
      ++result.load_steps;
      newton.failure.clear();
      if (newton.solve(factor, factor * target)) {
        done = factor;
        if (options.load_steps == 0) increment = std::min(1.0, 2.0 * increment);
        continue;
      }
      // Back to the last equilibrium with a smaller load increment.
      data.pose = pose;
      data.q = q;
      increment *= 0.5;
      if (increment < min_increment) {
        result.message = newton.failure + " (load step cut below 2^-20 at load factor " +
                         std::to_string(done) + ")";
        break;
      }
    }
    result.ok = done >= 1.0;
    if (result.ok && f_ref == 0.0) newton.residual = newton.residual_at(1.0);
    compute_wrenches(model, data, options.time, result.ok ? 1.0 : done);
    result.residual_norm = scaled_norm(wrench_vector(model, data), length);
    result.iterations = newton.iterations;
    result.singular_directions = newton.singular;
    if (newton.singular > 0)
      result.warnings.push_back(
          "the tangent stiffness has " + std::to_string(newton.singular) +
          " direction(s) without stiffness (a free mechanism); the equilibrium closest to the "
          "initial configuration along them is reported");
  } catch (const std::exception& e) {
    result.ok = false;
    result.message = e.what();
  }
  for (size_t r = 0; r < model.rails.size(); ++r)
    if (data.rail_floored[r])
      result.warnings.push_back("rail \"" + model.rails[r].name + "\" is at its min_length");
  result.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace beamrail
