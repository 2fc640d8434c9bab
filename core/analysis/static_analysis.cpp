#include "core/analysis/static_analysis.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "core/analysis/deformation_check.hpp"
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

// The residual that rounding alone leaves: element forces come from coordinates stored absolutely,
// so an element of axial stiffness EA/l at distance |p| from the origin carries force noise
// ~ eps EA |p| / l (bending adds far less). Newton cannot go below a small multiple of it.
double rounding_floor(const Model& model, const Data& data) {
  double floor = 0.0;
  const auto add = [&](const ElementEnds& e, double axial, double bending) {
    const double reach =
        std::max({data.pose[e.body1].c.norm(), data.pose[e.body2].c.norm(), e.length, 1e-300});
    floor =
        std::max(floor, (axial / e.length + bending / (e.length * e.length * e.length)) * reach);
  };
  for (const Beam& e : model.beams) add(e.ends, e.ea, 12.0 * std::max(e.eiy, e.eiz));
  for (const Rail& e : model.rails) add(e.ends, 0.0, 12.0 * std::max(e.eiy, e.eiz));
  return 16.0 * std::numeric_limits<double>::epsilon() * floor;
}

double scaled_norm(const Eigen::VectorXd& w, double length) {
  double n = 0.0;
  for (Eigen::Index i = 0; i < w.size(); ++i)
    n = std::max(n, std::abs(w(i)) / ((i % kDofsPerBody) < 3 ? 1.0 : length));
  return n;
}

// A factorized tangent, reused for the simplified Newton corrections of the monotonicity test.
// KLU factors it with the symbolic analysis of the topology's velocity-level pattern (6 x 6 per
// coupled body pair: exactly the tangent's), shared between designs. Falls back to the
// minimum-norm solution when the tangent is singular (free mechanisms).
class TangentSolver {
 public:
  explicit TangentSolver(std::shared_ptr<const SparseStructure> structure)
      : structure_(std::move(structure)) {
    klu_l_defaults(&common_);
  }
  ~TangentSolver() { free_numeric(); }
  TangentSolver(const TangentSolver&) = delete;
  TangentSolver& operator=(const TangentSolver&) = delete;

  bool factorize(const Model& model, const Data& data, std::string* failure) {
    matrix_ = stiffness_matrix(model, data);
    use_dense_ = false;
    null_directions = 0;
    if (!structure_) return factorize_dense();
    const JacobianPattern& p = structure_->reduced();
    values_.assign(p.rows.size(), 0.0);
    static_assert(kVelocityStates == kDofsPerBody, "the tangent's blocks are the pattern's");
    constexpr int n = kVelocityStates;
    for (size_t b = 0; b < data.stiffness.size(); ++b)
      for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c)
          values_[p.positions[b * n * n + n * r + c]] = data.stiffness[b](r, c);
    free_numeric();
    numeric_ =
        klu_l_factor(const_cast<long*>(p.column_starts.data()), const_cast<long*>(p.rows.data()),
                     values_.data(), structure_->symbolic(), &common_);
    if (numeric_ && klu_l_rcond(structure_->symbolic(), numeric_, &common_)) {
      const Eigen::VectorXd probe = Eigen::VectorXd::Ones(matrix_.rows());
      const Eigen::VectorXd x = solve(probe);
      if (x.allFinite()) {
        const Eigen::VectorXd r = matrix_ * x - probe;
        // Pivots within 1e8 of each other and a backward-stable solve: sound. (A long chain has
        // |S| |x| >> |b|: its residual is small relative to that, not to |b|; 1,000 segments
        // gave backward errors ~7e-17 with pivot ratios ~8e-5.) Otherwise one solve must leave
        // a residual small against |b|: a numerically singular matrix factorizes but solves
        // badly (a free carriage: pivot ratio ~1e-10).
        const double s_norm =
            Eigen::VectorXd(matrix_.cwiseAbs() * Eigen::VectorXd::Ones(matrix_.cols())).maxCoeff();
        if (common_.rcond > 1e-8 &&
            r.lpNorm<Eigen::Infinity>() <= 1e-12 * (s_norm * x.lpNorm<Eigen::Infinity>() + 1.0))
          return true;
        if (r.norm() <= 1e-8 * probe.norm()) return true;
      }
    }
    if (matrix_.rows() > 3000) {
      *failure = "the tangent stiffness is singular (a body or mechanism is free to move)";
      return false;
    }
    return factorize_dense();
  }
  // The minimum-norm solution by a complete orthogonal decomposition.
  bool factorize_dense() {
    const Eigen::MatrixXd dense(matrix_);
    cod_.setThreshold(1e-12);
    cod_.compute(dense);
    null_directions = static_cast<int>(dense.rows() - cod_.rank());
    use_dense_ = true;
    return true;
  }
  Eigen::VectorXd apply(const Eigen::VectorXd& x) const { return matrix_ * x; }
  Eigen::VectorXd solve(const Eigen::VectorXd& b) {
    if (use_dense_) return cod_.solve(b);
    Eigen::VectorXd x = b;
    if (!klu_l_solve(structure_->symbolic(), numeric_, x.size(), 1, x.data(), &common_))
      x.setConstant(std::numeric_limits<double>::quiet_NaN());
    return x;
  }
  int null_directions = 0;

 private:
  void free_numeric() {
    if (numeric_) klu_l_free_numeric(&numeric_, &common_);
  }
  std::shared_ptr<const SparseStructure> structure_;
  klu_l_common common_;
  klu_l_numeric* numeric_ = nullptr;
  std::vector<double> values_;
  Eigen::SparseMatrix<double> matrix_;
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod_;
  bool use_dense_ = false;
};

struct Newton {
  const Model& model;
  Data& data;
  double t, length;
  int max_iterations;
  int iterations = 0;
  int singular = 0;
  double residual = 0.0;
  std::string failure;
  TangentSolver solver;
  bool no_equilibrium = false;

  double residual_at(double factor) {
    compute_wrenches(model, data, t, factor);
    return scaled_norm(wrench_vector(model, data), length);
  }

  // Size of a correction in metres (rotations times the characteristic length).
  double size(const Eigen::VectorXd& dx) const {
    double sum = 0.0;
    for (Eigen::Index i = 0; i < dx.size(); ++i) {
      const double v = (i % kDofsPerBody) < 3 ? dx(i) : dx(i) * length;
      sum += v * v;
    }
    return std::sqrt(sum);
  }

  // Newton iterations at load factor `factor` from the current state; true when converged.
  //
  // Full Newton steps. With stiff axial and soft bending directions the linear predictor
  // stretches a bent beam and |R| jumps by orders of magnitude, yet the next step (whose tangent
  // sees the tension) removes it. Measured on the elastica (N = 4..64, P L^2/EI = 1..5): full
  // steps converge in 6-41 iterations; backtracking on |R| took 240-8500, and a monotonicity
  // test with the old tangent (which does not see the tension) stalled. So the line search only
  // backtracks (halving) from steps that make the forces non-finite; divergence is caught by the
  // iteration limit and answered by a smaller load step.
  // target: the residual asked for; floor: what rounding alone leaves (rounding_floor). A
  // residual below 10 floor that Newton no longer reduces is converged; a correction below the
  // resolution of the coordinates with a residual above that means the loads push along a
  // direction without stiffness, and is a failure, never an equilibrium.
  bool solve(double factor, double target, double floor) {
    double r = residual_at(factor), best = r;
    int rising = 0, stalled = 0;
    for (int it = 0; it < max_iterations; ++it) {
      if (r <= target || (r <= 10.0 * floor && stalled >= 2)) {
        residual = r;
        return true;
      }
      compute_tangent(model, data, t, false, factor);
      const Eigen::VectorXd w = wrench_vector(model, data);
      ++iterations;
      if (!solver.factorize(model, data, &failure)) return false;
      singular = std::max(singular, solver.null_directions);
      const Eigen::VectorXd dx = solver.solve(-w);
      if (!dx.allFinite()) {
        failure = "the tangent stiffness is singular";
        return false;
      }
      if (solver.null_directions > 0 && scaled_norm(solver.apply(dx) + w, length) >
                                            std::max(1e-6 * scaled_norm(w, length), 10.0 * floor)) {
        failure =
            "the loads push along a direction without stiffness (a free mechanism, such as a "
            "carriage pushed along its rails): there is no equilibrium";
        no_equilibrium = true;
        return false;
      }
      if (size(dx) <= 1e-14 * length) {
        residual = r;
        if (r <= 10.0 * floor) return true;  // converged to rounding
        failure =
            "the loads cannot be balanced (the Newton correction vanishes while the residual "
            "stays at " +
            std::to_string(r) + " N)";
        return false;
      }
      const std::vector<Pose<double>> pose = data.pose;
      const std::vector<Vec4> q = data.q;
      const auto trial = [&](double fraction) {
        data.pose = pose;
        data.q = q;
        apply_increment(model, data, fraction * dx);
        return residual_at(factor);
      };
      double value = trial(1.0);
      for (double fraction = 0.5; !std::isfinite(value) && fraction > 1e-3; fraction *= 0.5)
        value = trial(fraction);
      if (!std::isfinite(value)) {
        data.pose = pose;
        data.q = q;
        failure = "Newton steps lead to non-finite forces";
        return false;
      }
      rising = value > r ? rising + 1 : 0;
      stalled = value < 0.5 * best ? 0 : stalled + 1;
      best = std::min(best, value);
      r = value;
      if (rising >= 8) {
        failure = "Newton diverges (the residual grew 8 times in a row)";
        return false;
      }
    }
    residual = r;
    if (r <= target) return true;
    failure = "Newton did not converge in " + std::to_string(max_iterations) +
              (max_iterations == 1 ? " iteration" : " iterations");
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
    std::shared_ptr<const SparseStructure> structure;  // none without free bodies: nothing to solve
    if (model.n_free() > 0)
      structure = options.structure_cache ? options.structure_cache->get(model)
                                          : std::make_shared<const SparseStructure>(model);
    Newton newton{model, data, options.time, length, options.max_iterations,
                  0,     0,    0.0,          {},     TangentSolver(std::move(structure)),
                  false};
    const double floor = rounding_floor(model, data);

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
      if (newton.solve(factor, factor * options.tolerance * f_ref, floor)) {
        done = factor;
        if (options.load_steps == 0) increment = std::min(1.0, 2.0 * increment);
        continue;
      }
      // Back to the last equilibrium with a smaller load increment (unless no increment can
      // help: the loads have no equilibrium at all).
      data.pose = pose;
      data.q = q;
      increment *= 0.5;
      if (newton.no_equilibrium || increment < min_increment) {
        char where[120];
        std::snprintf(where, sizeof where, " (at load factor %.6g, %d load steps)", factor,
                      result.load_steps);
        result.message = newton.failure + where;
        break;
      }
    }
    result.ok = done >= 1.0;
    if (result.ok && f_ref == 0.0) newton.residual = newton.residual_at(1.0);
    compute_wrenches(model, data, options.time, result.ok ? 1.0 : done);
    result.residual_norm = scaled_norm(wrench_vector(model, data), length);
    result.iterations = newton.iterations;
    if (result.ok && !(result.residual_norm <= std::max(options.tolerance * f_ref, 10.0 * floor))) {
      // Never an equilibrium that does not balance the loads.
      result.ok = false;
      char text[160];
      std::snprintf(text, sizeof text, "the residual %.3g N does not balance the loads",
                    result.residual_norm);
      result.message = text;
    }
    if (result.ok && result.residual_norm > std::max(options.tolerance, 1e-6) * f_ref) {
      char text[200];
      std::snprintf(text, sizeof text,
                    "rounding limited the static residual to %.3g N (%.3g of the load): stiff "
                    "elements far from the origin",
                    result.residual_norm, result.residual_norm / std::max(f_ref, 1e-300));
      result.warnings.push_back(text);
    }
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
  DeformationCheck deformation(model);
  deformation.observe(model, data, options.time);
  for (std::string& w : deformation.warnings(model, false)) result.warnings.push_back(std::move(w));
  result.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace beamrail
