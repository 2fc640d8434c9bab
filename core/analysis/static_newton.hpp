// The Newton machinery of the static analysis (core/analysis/static_analysis.hpp): the load and
// motion scales, the factorized tangent and Newton's iterations at a load factor. Shared by load
// control (static_analysis.cpp) and arc-length control (static_path.cpp); not a public interface.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/analysis/deadline.hpp"
#include "core/analysis/deformation_check.hpp"
#include "core/analysis/sparse_structure.hpp"
#include "core/analysis/static_analysis.hpp"
#include "core/model/element_kinematics.hpp"
#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"

namespace beamrail::statics {

inline constexpr double kEps = std::numeric_limits<double>::epsilon();
// Load steps in a row, each half the last, that may find "no equilibrium" before the analysis
// gives up with it.
inline constexpr int kNoEquilibriumRetries = 4;

inline std::string format(const char* pattern, double a, double b = 0.0) {
  char text[400];
  std::snprintf(text, sizeof text, pattern, a, b);
  return text;
}

// The load scale: the largest applied force (moments / length) or weight, at full load.
inline double reference_force(const Model& model, double t, double length) {
  double f = 0.0;
  for (int i : model.free_bodies)
    f = std::max(f, model.bodies[i].mass * model.gravity.stableNorm());
  for (const Load& load : model.loads) {
    const double v = std::abs(load.time(t)) * load.value.stableNorm();
    f = std::max(f, load.kind == LoadKind::kForce ? v : v / length);
  }
  return f;
}

inline double scaled_norm(const Eigen::VectorXd& w, double length) {
  double n = 0.0;
  for (Eigen::Index i = 0; i < w.size(); ++i)
    n = std::max(n, std::abs(w(i)) / ((i % kDofsPerBody) < 3 ? 1.0 : length));
  return n;
}

// Size of a motion in metres (rotations times the characteristic length).
inline double motion_size(const Eigen::VectorXd& x, double length) {
  double sum = 0.0;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    const double v = (i % kDofsPerBody) < 3 ? x(i) : x(i) * length;
    sum += v * v;
  }
  return std::sqrt(sum);
}

// The displacement of every free body from the initial configuration (u, rotation vector).
inline Eigen::VectorXd displacement(const Model& model, const Data& data) {
  Eigen::VectorXd x(model.n_dofs);
  for (int k = 0; k < model.n_free(); ++k) {
    const int i = model.free_bodies[k];
    x.segment<3>(kDofsPerBody * k) = data.pose[i].u;
    x.segment<3>(kDofsPerBody * k + 3) = data.rotation[i];
  }
  return x;
}

// The smallest ratio of KLU's pivots (rcond) that is still a stiffness rather than a direction
// without one. 1e-8 for a compact structure. A chain of n elements in series has physical pivot
// ratios down to about 1 / (4 n^3) (the stiffness of an n-segment cantilever at its tip against
// that of one segment: a 512-chord bend has 2e-9), so a structure whose every body is held by
// beams (no mechanism is possible) accepts pivots down to 1e-8 / n^3, with n its total element
// length over its shortest element, but not below 1e-14, where rounding begins; a structure that
// is not held may be a mechanism (a free carriage: 1e-10), and keeps 1e-8. Joints are stiffer than
// the stiffest element by 1 / c (c their relative compliance, docs/model.md "Joints"), which
// spreads the pivots of a held structure by as much: its floor is c times lower (a 600-segment
// cantilever clamped and welded by fixed joints at c = 1e-6: rcond 3e-15, its solves backward
// stable and its deflection P L^3 / 3 EI to 4e-8, tests/core/analysis/joint_elements_test.cpp).
inline double pivot_floor(const Model& model) {
  if (!held_by_beams(model)) return 1e-8;
  double total = 0.0, shortest = INFINITY;
  for (const Beam& e : model.beams) {
    total += e.ends.length;
    shortest = std::min(shortest, e.ends.length);
  }
  double compliance = 1.0;
  for (const Joint& j : model.joints) compliance = std::min(compliance, j.relative_compliance);
  const double n = shortest > 0.0 && std::isfinite(total / shortest) ? total / shortest : 1.0;
  return std::max(1e-8 / std::pow(std::max(n, 1.0), 3), 1e-14) * compliance;
}

// A factorized tangent. KLU factors it with the symbolic analysis of the topology's velocity-level
// pattern (6 x 6 per coupled body pair: exactly the tangent's), shared between designs. Falls back
// to the minimum-norm solution of a dense decomposition when KLU's factors are unsound (free
// mechanisms, or a tangent whose entries span too many decades for its pivot test). That one sees
// the tangent equilibrated by its diagonal, D S D with D = |diag S|^-1/2, so that its rank test
// compares like with like: forces per metre and moments per radian can differ by orders of
// magnitude (a 1 nm beam: 12 EI / l^3 = 2e30 N/m beside 4 EI / l = 7e11 N m).
class TangentSolver {
 public:
  explicit TangentSolver(std::shared_ptr<const SparseStructure> structure)
      : structure_(std::move(structure)) {
    klu_l_defaults(&common_);
  }
  ~TangentSolver() { free_numeric(); }
  TangentSolver(const TangentSolver&) = delete;
  TangentSolver& operator=(const TangentSolver&) = delete;

  // Largest tangent that a singular or ill-conditioned factorization falls back to the dense
  // minimum-norm solution for (n^3: about 3 s at 3,000 rows); above it factorize() fails.
  long dense_limit = 3000;

  // The tangent's values in the pattern's compressed columns (matrix() views them).
  bool factorize(const Model& model, const Data& data, std::string* failure) {
    use_dense_ = false;
    null_directions = 0;
    const JacobianPattern& p = structure_->reduced();
    values_.assign(p.rows.size(), 0.0);
    static_assert(kVelocityStates == kDofsPerBody, "the tangent's blocks are the pattern's");
    constexpr int n = kVelocityStates;
    for (size_t b = 0; b < data.stiffness.size(); ++b)
      for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c)
          values_[p.positions[b * n * n + n * r + c]] = data.stiffness[b](r, c);
    const Matrix s = matrix();
    long* starts = const_cast<long*>(p.column_starts.data());  // KLU reads only
    long* rows = const_cast<long*>(p.rows.data());
    // The previous pivots while their growth stays within 1e3 of fresh partial pivoting (as the
    // transient's solver does): a refactorization allocates nothing, which on a 100,000-body chain
    // halved the time of a Newton iteration.
    if (numeric_ &&
        !(klu_l_refactor(starts, rows, values_.data(), structure_->symbolic(), numeric_,
                         &common_) &&
          common_.status == KLU_OK &&
          klu_l_rgrowth(starts, rows, values_.data(), structure_->symbolic(), numeric_, &common_) &&
          common_.rgrowth >= 1e-3 * fresh_growth_))
      free_numeric();
    if (!numeric_) {
      numeric_ = klu_l_factor(starts, rows, values_.data(), structure_->symbolic(), &common_);
      if (numeric_ &&
          klu_l_rgrowth(starts, rows, values_.data(), structure_->symbolic(), numeric_, &common_))
        fresh_growth_ = common_.rgrowth;
    }
    if (numeric_ && klu_l_rcond(structure_->symbolic(), numeric_, &common_)) {
      const Eigen::VectorXd probe = Eigen::VectorXd::Ones(s.rows());
      const Eigen::VectorXd x = solve(probe);
      if (x.allFinite()) {
        const Eigen::VectorXd r = s * x - probe;
        // Pivots within 1e8 of each other and a backward-stable solve: sound. (A long chain has
        // |S| |x| >> |b|: its residual is small relative to that, not to |b|; 1,000 segments
        // gave backward errors ~7e-17 with pivot ratios ~8e-5.) Otherwise one solve must leave
        // a residual small against |b|: a numerically singular matrix factorizes but solves
        // badly (a free carriage: pivot ratio ~1e-10).
        const double s_norm = abs_times(Eigen::VectorXd::Ones(s.cols())).maxCoeff();
        if (floor_ < 0.0) floor_ = pivot_floor(model);
        const bool stable =
            r.lpNorm<Eigen::Infinity>() <= 1e-12 * (s_norm * x.lpNorm<Eigen::Infinity>() + 1.0);
        if (stable && (common_.rcond > floor_ || keep_near_singular)) return true;
        if (r.norm() <= 1e-8 * probe.norm()) return true;
      }
    }
    if (s.rows() > dense_limit) {
      *failure = held_by_beams(model)
                     ? "the tangent stiffness is singular or indefinite: the structure buckles or "
                       "snaps through under these loads"
                     : "the tangent stiffness is singular: a body or mechanism is free to move, "
                       "or the structure buckles under these loads";
      return false;
    }
    return factorize_dense();
  }
  // The minimum-norm solution by a complete orthogonal decomposition.
  bool factorize_dense() {
    const Eigen::SparseMatrix<double> s = matrix();
    scale_.resize(s.rows());
    for (Eigen::Index i = 0; i < s.rows(); ++i) {
      const double d = std::abs(s.coeff(i, i));
      scale_(i) = d > 0.0 && std::isfinite(d) ? 1.0 / std::sqrt(d) : 1.0;
    }
    const Eigen::MatrixXd dense = scale_.asDiagonal() * Eigen::MatrixXd(s) * scale_.asDiagonal();
    cod_.setThreshold(1e-12);
    cod_.compute(dense);
    null_directions = static_cast<int>(dense.rows() - cod_.rank());
    use_dense_ = true;
    return true;
  }
  Eigen::VectorXd apply(const Eigen::VectorXd& x) const { return matrix() * x; }
  // S^-1 b (the minimum-norm solution, in the equilibrated variables, when S is singular).
  Eigen::VectorXd solve(const Eigen::VectorXd& b) {
    if (use_dense_) return scale_.cwiseProduct(cod_.solve(scale_.cwiseProduct(b)));
    Eigen::VectorXd x = b;
    if (!klu_l_solve(structure_->symbolic(), numeric_, x.size(), 1, x.data(), &common_))
      x.setConstant(std::numeric_limits<double>::quiet_NaN());
    return x;
  }
  // What rounding leaves in a residual evaluated at displacement x: the stiffness terms that
  // cancel in it each carry eps of their size, eps |S| (|x| + r), where r (the element length for
  // translations, 1 rad for rotations) stands for the rounding of the element chords and relative
  // rotations themselves (scaled like the residual).
  double rounding_floor(const Eigen::VectorXd& x, double length) const {
    Eigen::VectorXd reach = x.cwiseAbs();
    for (Eigen::Index i = 0; i < reach.size(); ++i)
      reach(i) += (i % kDofsPerBody) < 3 ? length : 1.0;
    return scaled_norm(kEps * abs_times(reach), length);
  }
  // What rounding leaves in the residual of a solve S dx = b: eps |S| |dx| (scaled like the
  // residual). The minimum-norm solve of a tangent whose soft directions are many decades below
  // its stiff ones (the penalty of a joint) leaves that much, however exact the equilibrium.
  double solve_rounding(const Eigen::VectorXd& dx, double length) const {
    return scaled_norm(kEps * abs_times(dx.cwiseAbs()), length);
  }
  int null_directions = 0;
  // Keep a backward-stable factorization however small its pivot ratio (arc-length control: near
  // a limit point the tangent is nearly singular, and the path needs its true solutions, not the
  // minimum-norm ones that drop the direction the structure gives way in).
  bool keep_near_singular = false;

 private:
  void free_numeric() {
    if (numeric_) klu_l_free_numeric(&numeric_, &common_);
  }

  std::shared_ptr<const SparseStructure> structure_;
  klu_l_common common_;
  klu_l_numeric* numeric_ = nullptr;
  std::vector<double> values_;
  using Matrix = Eigen::Map<const Eigen::SparseMatrix<double, Eigen::ColMajor, long>>;
  Matrix matrix() const {
    const JacobianPattern& p = structure_->reduced();
    const long n = static_cast<long>(p.column_starts.size()) - 1;
    return Matrix(n, n, p.nnz(), p.column_starts.data(), p.rows.data(), values_.data());
  }
  // |S| v without forming |S|.
  Eigen::VectorXd abs_times(const Eigen::VectorXd& v) const {
    const JacobianPattern& p = structure_->reduced();
    Eigen::VectorXd out = Eigen::VectorXd::Zero(v.size());
    for (Eigen::Index c = 0; c < v.size(); ++c)
      for (long k = p.column_starts[c]; k < p.column_starts[c + 1]; ++k)
        out(p.rows[k]) += std::abs(values_[k]) * std::abs(v(c));
    return out;
  }
  Eigen::VectorXd scale_;      // D of the dense decomposition
  double fresh_growth_ = 1.0;  // reciprocal pivot growth of the last factorization with pivoting
  double floor_ = -1.0;        // pivot_floor of the model (computed at the first factorization)
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod_;
  bool use_dense_ = false;
};

struct Newton {
  Newton(const Model& m, Data& d, double time, double len, int max_it, const Deadline& b,
         std::shared_ptr<const SparseStructure> structure)
      : model(m),
        data(d),
        t(time),
        length(len),
        max_iterations(max_it),
        budget(b),
        solver(std::move(structure)) {}
  const Model& model;
  Data& data;
  double t, length;
  int max_iterations;
  const Deadline& budget;
  TangentSolver solver;
  const bool held = held_by_beams(model);  // every free body held by beams to a fixed body
  int iterations = 0;
  int singular = 0;       // null directions: the most at any iterate
  int last_singular = 0;  // null directions at the last iterate
  // The null directions a result reports: for a structure held by beams those met along the
  // load path (a limit or bifurcation point passed), for a mechanism those of its equilibrium
  // (a pendulum's swing has none once its joint carries the bob, though the unloaded start had).
  int reported_singular() const { return held ? singular : last_singular; }
  double residual = 0.0;
  double floor = 0.0;       // rounding floor at the last tangent
  double correction = 0.0;  // last correction / displacement
  std::string failure;
  bool final = false;        // no smaller load step can help (no equilibrium, precision, budget)
  int no_equilibrium = 0;    // load steps in a row that found no equilibrium
  bool pushes_free = false;  // the last failure: the loads push a free body, mechanism or carriage

  struct Saved {
    std::vector<Pose<double>> pose;
    std::vector<Vec4> q;
    std::vector<Vec3> rotation;
  };
  Saved save() const { return {data.pose, data.q, data.rotation}; }
  void restore(const Saved& s) {
    data.pose = s.pose;
    data.q = s.q;
    data.rotation = s.rotation;
  }

  double residual_at(double factor) {
    compute_wrenches(model, data, t, factor);
    return scaled_norm(wrench_vector(model, data), length);
  }

  bool fail(std::string why, bool no_smaller_step, bool pushed_free = false) {
    failure = std::move(why);
    final = no_smaller_step;
    pushes_free = pushed_free;
    return false;
  }

  // The carriages' positions along their rails (xi_x) in the current configuration.
  std::vector<double> carriage_positions() const {
    std::vector<double> out;
    for (const Rail& e : model.rails)
      out.push_back(element_frames(e.ends, data.pose[e.ends.body1], data.pose[e.ends.body2],
                                   rotation_measure(e))
                        .xi(0));
    return out;
  }

  // A carriage that a Newton iterate moved along its rail by more than kRailTravelWarning times
  // its distance from point 1 at the start of the load step: the loads push it along the rail,
  // where nothing holds it (a smaller load step is tried; a carriage that runs away at every load
  // step has no equilibrium).
  std::string runaway_carriage(const std::vector<double>& start) const {
    const std::vector<double> now = carriage_positions();
    for (size_t k = 0; k < model.rails.size(); ++k) {
      const Rail& e = model.rails[k];
      if (std::abs(now[k] - start[k]) >
          kRailTravelWarning * std::max(std::abs(start[k]), e.min_length))
        return "the carriage of rail \"" + e.name +
               "\" ran away along the rail in a Newton iterate " +
               format(
                   "(from %.3g m to %.3g m from point 1): the loads push it along the rail, "
                   "which does not hold it: there is no equilibrium",
                   start[k], now[k]);
    }
    return "";
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
  //
  // Converged: the residual is below `target`, or it is at the rounding floor (eps |S| |x|) and
  // the correction no longer moves the solution (below kCorrectionTolerance of it). A residual
  // that stays at the floor while the corrections do not shrink is rounding-limited: the
  // equilibrium cannot be resolved in double precision, and no load step helps.
  bool solve(double factor, double target) {
    double r = residual_at(factor);
    if (!std::isfinite(r))
      return fail(
          "the forces are not finite (the loads or the stiffness overflow double precision)", true);
    const std::vector<double> carriages = carriage_positions();
    int rising = 0;
    int noisy = 0;             // iterations in a row with the residual near its rounding floor
    double noisy_first = 0.0;  // the correction at the first of them
    int settled = 0;           // iterations in a row near the floor with corrections that small
    double pushed = -1.0;      // what the last iterate's loads pushed along its null
                               // directions (-1: they did not)
    for (int it = 0; it < max_iterations; ++it) {
      if (r <= target) {
        residual = r;
        return true;
      }
      if (budget.passed())
        return fail("the static analysis did not finish within its time budget", true);
      compute_tangent(model, data, t, false, factor);
      const Eigen::VectorXd w = wrench_vector(model, data);
      ++iterations;
      std::string why;
      if (!solver.factorize(model, data, &why)) return fail(why, false);
      singular = std::max(singular, solver.null_directions);
      last_singular = solver.null_directions;
      Eigen::VectorXd dx = solver.solve(-w);
      if (!dx.allFinite()) return fail("the tangent stiffness is singular", false);
      // A minimum-norm solve that leaves more of the forces than 1e-6 of them, the rounding
      // floor and the solve's own rounding (a bob on a revolute joint at a cantilever's tip, c =
      // 1e-6: 6e-6 of the forces, a third of eps |S| |dx|) pushes along its null directions.
      const double left = solver.null_directions > 0
                              ? scaled_norm(solver.apply(dx) + w, length)
                              : 0.0;  // what the minimum-norm step leaves of the forces
      const bool pushes = left > std::max({1e-6 * scaled_norm(w, length), 10.0 * floor,
                                           10.0 * solver.solve_rounding(dx, length)});
      // A mechanism's stiffness may come from the loads it carries: a pendulum released off the
      // vertical from an unloaded joint has no stiffness in its swing until the joint carries
      // the bob's weight, and gravity pushes along the swing. So a mechanism goes on with the
      // minimum-norm step (it loads the joint) while what the loads push along its null
      // directions falls (to a tenth at least per iterate: a 3 kg bob on a revolute joint
      // tilted 5 degrees left 0.83 of its 29 N, then none; on a spherical joint 1.02, then
      // 1.2e-4, then none), and fails when it does not (a carriage pushed along its rail pushes
      // as much at the next iterate).
      const bool going_on = pushes && !held && (pushed < 0.0 || left < 0.1 * pushed);
      pushed = pushes ? left : -1.0;
      if (pushes && !going_on) {
        // Every body held by beams: no mechanism, the tangent lost its stiffness under the
        // loads (buckling, a snap, an element at the end of its law's range); a smaller load
        // step may pass. Otherwise a free body or mechanism is pushed: no load step helps.
        if (held)
          return fail(
              "the tangent stiffness became singular along the loads (the structure "
              "buckles or snaps through, or an element reaches the end of its law's "
              "range)",
              false);
        // A smaller load step is tried (kNoEquilibriumRetries times in a row at most): an
        // iterate far from the path may meet a direction without stiffness that the
        // equilibrium does not have.
        ++no_equilibrium;
        return fail(
            "the loads push along a direction without stiffness (a free mechanism, such as a "
            "carriage pushed along its rails): there is no equilibrium",
            no_equilibrium > kNoEquilibriumRetries, true);
      }
      const Eigen::VectorXd x = displacement(model, data);
      floor = solver.rounding_floor(x, length);
      const double size = motion_size(x, length);
      correction = size > 0.0 ? motion_size(dx, length) / size : INFINITY;
      // At the rounding floor a correction this small is rounding noise: the last one is applied.
      // So too near it (within 100 times) once three corrections in a row are that small: the floor
      // estimate can miss rounding by more than its factor 10 (a cantilever of 32 segments 10 m
      // from the origin, bent into an arc by a follower torque, stayed at 14 times it while its
      // corrections were 1e-14 of the displacement, and failed as rounding-limited).
      settled = r <= 1e2 * floor && correction <= kCorrectionTolerance ? settled + 1 : 0;
      const bool converged =
          (r <= 10.0 * floor && correction <= kCorrectionTolerance) || settled >= 3;
      // At most kMaxRotationStep of rotation per body in one iterate.
      double turn = 0.0;
      for (int k = 0; k < model.n_free(); ++k)
        turn = std::max(turn, dx.segment<3>(kDofsPerBody * k + 3).norm());
      if (turn > kMaxRotationStep) dx *= kMaxRotationStep / turn;
      if (converged) {
        apply_increment(model, data, dx);
        residual = residual_at(factor);
        if (std::isfinite(residual)) return true;
        return fail("the forces are not finite", false);
      }
      const Saved saved = save();
      const auto trial = [&](double fraction) {
        restore(saved);
        apply_increment(model, data, fraction * dx);
        return residual_at(factor);
      };
      double value = trial(1.0);
      for (double fraction = 0.5; !std::isfinite(value) && fraction > 1e-3; fraction *= 0.5)
        value = trial(fraction);
      if (!std::isfinite(value)) {
        restore(saved);
        return fail("Newton steps lead to non-finite forces", false);
      }
      if (std::string away = runaway_carriage(carriages); !away.empty())
        return fail(away, false, true);
      if (std::string turned = element_turned_beyond(model, data, kIterateRotationLimit);
          !turned.empty())
        return fail(turned + " in a Newton iterate", false);
      rising = value > r ? rising + 1 : 0;
      // Near the floor Newton converges in a few iterations (each correction a fraction of the
      // previous one); corrections that keep their size there are moved by rounding alone.
      if (r <= 1e3 * floor) {
        noisy_first = noisy == 0 ? correction : noisy_first;
        ++noisy;
      } else {
        noisy = 0;
      }
      r = value;
      if ((noisy >= 6 && correction > 1e-2 * noisy_first) || noisy >= 12)
        return fail("rounding errors limit this equilibrium: the residual stays at " +
                        format("%.3g N (rounding floor %.3g N)", r, floor) +
                        format(" while the Newton corrections still move the solution by %.2g "
                               "of its size; the stiffness terms of this scene cancel beyond "
                               "double precision (chains of very many short segments): use "
                               "fewer segments",
                               correction),
                    true);
      if (rising >= 8) return fail("Newton diverges (the residual grew 8 times in a row)", false);
    }
    residual = r;
    if (r <= target) return true;
    return fail("Newton did not converge in " + std::to_string(max_iterations) +
                    (max_iterations == 1 ? " iteration" : " iterations"),
                false);
  }
};

// Arc-length control (static_path.cpp): follows the load-displacement path from the unloaded
// start with the load factor as an unknown until it reaches 1, then solves the equilibrium at the
// full loads from there (*done = 1, true); false with result.message when it cannot. Fills
// result.path, path_bodies, limit_load_factor and load_steps either way.
bool follow_path(Newton& newton, const StaticOptions& options, double f_ref, StaticResult& result,
                 double* done);

}  // namespace beamrail::statics
