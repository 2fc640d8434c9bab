#include "core/analysis/static_analysis.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "core/analysis/axial_force_check.hpp"
#include "core/analysis/deadline.hpp"
#include "core/analysis/deformation_check.hpp"
#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/static_newton.hpp"
#include "core/model/element_kinematics.hpp"
#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"

namespace beamrail {
namespace {

using Clock = std::chrono::steady_clock;
using namespace statics;

// Stability of the equilibrium in data.pose.
struct Stability {
  int negative = 0;  // directions of negative stiffness (divergence)
  int flutter = 0;   // pairs of vibrations that grow (non-conservative loads only)
};

// Under conservative loads the tangent K is symmetric at an equilibrium: the negative pivots of
// an LDL^T of K count its negative eigenvalues (Sylvester's law of inertia), shifted by a small
// multiple of the mass where rigid-body or mechanism directions (zero stiffness) may exist.
// Torques of fixed direction and follower loads do no conservative work and make K
// non-symmetric: its symmetric part
// says nothing then (a clamped beam bent into a circle by a tip torque is stable, its symmetric
// part indefinite). The small vibrations M x'' + K x = 0 are bounded when every eigenvalue of
// K x = lambda M x is real and positive: a negative one diverges, a complex pair flutters. Up to
// kDenseStabilityLimit degrees of freedom all eigenvalues are computed (~5 ms; 600 took 0.4 s);
// beyond, the kNearStabilityCount nearest zero (Arnoldi), where loads move eigenvalues across
// zero or make two of them meet, and the sign of det K (an odd number of negative ones anywhere).
constexpr Eigen::Index kDenseStabilityLimit = 120;
// The imaginary part below which an eigenvalue is real, in multiples of kEps times the largest
// stiffness over mass: the absolute rounding of the computed eigenvalues (count_unstable).
constexpr double kStabilityNoise = 100.0;
// The share of the load an equilibrium with directions solved minimum-norm may leave unbalanced
// (studies/hinged_bob.json leaves 1.4e-5 of its load; the review's hinge 1e-2 times as compliant
// left 0.75).
constexpr double kMostUnbalancedShare = 1e-3;
constexpr Eigen::Index kNearStabilityCount = 12;

// An eigenvalue's imaginary part counts as flutter beyond 1e-6 of its size and beyond `noise`,
// the rounding of the whole problem's eigenvalues (a multiple of kEps times the largest
// stiffness over mass): a hanging chain of three on spherical joints has three spins without
// stiffness, shifted to mu, whose rounding (eigenvalues mu +- 2e-9 i where mu = 5.2e-4 and
// kEps times the largest stiffness over mass is 5.2e-8) read as a growing pair and failed its
// static analysis as unstable (found 2026-12-01).
void count_unstable(const Eigen::VectorXcd& values, double mu, double noise, Stability& result) {
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    const double size = std::max(std::abs(values(i)), mu);
    if (std::abs(values(i).imag()) > std::max(1e-6 * size, noise))
      result.flutter += values(i).imag() > 0.0;
    else
      result.negative += values(i).real() < 0.0;
  }
}

Stability stability(const Model& model, Data& data, double t) {
  compute_tangent(model, data, t, false, 1.0);
  double asymmetry = 0.0;
  Eigen::SparseMatrix<double> k =
      symmetric_stiffness(model, data, stiffness_weights(model, data), &asymmetry);
  const Eigen::SparseMatrix<double> m = mass_matrix(model, data);
  double scale = 0.0;  // the largest stiffness over mass [1/s^2]
  for (Eigen::Index i = 0; i < k.rows(); ++i)
    scale = std::max(scale, std::abs(k.coeff(i, i)) / m.coeff(i, i));
  if (!(scale > 0.0 && std::isfinite(scale))) scale = 1.0;
  const double mu = held_by_beams(model) ? 0.0 : 1e4 * kEps * scale;
  const double noise = kStabilityNoise * kEps * scale;
  Stability result;
  if (asymmetry <= kModalAsymmetryLimit) {
    k += mu * m;
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(k);
    if (ldlt.info() != Eigen::Success) {  // a zero pivot: singular, not stable
      result.negative = 1;
      return result;
    }
    result.negative = static_cast<int>((ldlt.vectorD().array() < 0.0).count());
    return result;
  }
  Eigen::SparseMatrix<double> full = -stiffness_matrix(model, data);
  full += mu * m;
  Eigen::VectorXcd values;
  if (full.rows() <= kDenseStabilityLimit) {
    if (!solve_dense_nonsymmetric(Eigen::MatrixXd(full), Eigen::MatrixXd(m), values))
      result.negative = 1;
    else
      count_unstable(values, mu, noise, result);
    return result;
  }
  // K + mu M: the shift moves rigid directions off zero; the eigenvalues nearest 0.
  if (!nonsymmetric_eigenvalues_near(full, m, 0.0, kNearStabilityCount, values)) {
    result.negative = 1;
    return result;
  }
  count_unstable(values, mu, noise, result);
  if (result.negative == 0) {
    full.makeCompressed();
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(full);
    if (lu.info() != Eigen::Success || lu.signDeterminant() < 0.0) result.negative = 1;
  }
  return result;
}

}  // namespace

namespace {

bool refuse_options(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

}  // namespace

bool StaticOptions::IsValid(std::string* error) const {
  if (std::isnan(time)) return refuse_options(error, "time must be a number");
  if (load_steps < 0) return refuse_options(error, "load_steps must be 0 (automatic) or more");
  if (max_iterations < 1) return refuse_options(error, "max_iterations must be at least 1");
  if (!(tolerance > 0.0 && std::isfinite(tolerance)))
    return refuse_options(error, "tolerance must be positive and finite");
  if (max_load_steps < 1) return refuse_options(error, "max_load_steps must be at least 1");
  if (!(arc_length >= 0.0 && std::isfinite(arc_length)))
    return refuse_options(error, "arc_length must be 0 (automatic) or positive and finite");
  if (!(max_seconds >= 0.0 && std::isfinite(max_seconds)))
    return refuse_options(error, "max_seconds must be 0 (no budget) or positive and finite");
  return true;
}

StaticResult solve_static(const Model& model, const StaticOptions& options, Data& data) {
  const auto start = Clock::now();
  StaticResult result;
  if (!options.IsValid(&result.message)) {
    result.message = "invalid static options: " + result.message;
    return result;
  }
  const Deadline budget(start, options.max_seconds);
  try {
    reset_to_initial(model, data);
    const double length = characteristic_length(model);
    const double f_ref = reference_force(model, options.time, length);
    result.reference_force = f_ref;
    if (!std::isfinite(f_ref))
      throw std::runtime_error("the loads are out of the range of double precision");
    std::shared_ptr<const SparseStructure> structure;  // none without free bodies: nothing to solve
    if (model.n_free() > 0)
      structure = options.structure_cache ? options.structure_cache->get(model)
                                          : std::make_shared<const SparseStructure>(model);
    Newton newton(model, data, options.time, length, options.max_iterations, budget,
                  std::move(structure));

    // Without loads the initial configuration, stress-free by construction, is the equilibrium.
    double done = f_ref > 0.0 && model.n_free() > 0 ? 0.0 : 1.0;
    double increment = options.load_steps > 0 ? 1.0 / options.load_steps : 1.0;
    const double min_increment = 1.0 / (1 << 20);
    bool path_ok = true;
    if (done < 1.0 && options.control == StaticControl::kArcLength) {
      path_ok = follow_path(newton, options, f_ref, result, &done);
      if (!path_ok) result.timed_out = budget.passed();
    }
    while (done < 1.0 && options.control == StaticControl::kLoad) {
      if (result.load_steps >= options.max_load_steps) {
        result.message = "more than " + std::to_string(options.max_load_steps) + " load steps";
        break;
      }
      const double factor = std::min(1.0, done + increment);
      const Newton::Saved saved = newton.save();
      ++result.load_steps;
      newton.failure.clear();
      if (newton.solve(factor, factor * options.tolerance * f_ref)) {
        done = factor;
        newton.no_equilibrium = 0;
        if (options.load_steps == 0) increment = std::min(1.0, 2.0 * increment);
        continue;
      }
      // Back to the last equilibrium with a smaller load increment (unless no increment can
      // help: no equilibrium, rounding, the budget).
      newton.restore(saved);
      increment *= 0.5;
      if (newton.final || increment < min_increment) {
        result.no_equilibrium = newton.pushes_free;
        result.message = newton.failure + format(" (at load factor %.6g, ", factor) +
                         std::to_string(result.load_steps) +
                         (result.load_steps == 1 ? " load step)" : " load steps)");
        // An element near the end of its law's range explains most such failures.
        if (std::string edge = element_out_of_range(model, data, 0.8); !edge.empty())
          result.message = format("at load factor %.6g, ", done) + edge +
                           "; beyond it the Newton iterations failed: " + result.message;
        result.timed_out = budget.passed();
        break;
      }
    }
    result.ok = done >= 1.0 && path_ok;
    compute_wrenches(model, data, options.time, result.ok ? 1.0 : done);
    result.residual_norm = scaled_norm(wrench_vector(model, data), length);
    result.iterations = newton.iterations;
    result.rounding_floor = newton.floor;
    result.correction = newton.correction;
    result.singular_directions = newton.singular;
    if (result.ok && !std::isfinite(result.residual_norm)) {
      result.ok = false;
      result.message = "the forces are not finite at the equilibrium";
    }
    if (result.ok) {
      if (std::string range = element_out_of_range(model, data); !range.empty()) {
        result.ok = false;
        result.message = range;
      }
    }
    if (result.ok && model.n_free() > 0) {
      const Stability stable = stability(model, data, options.time);
      result.negative_directions = stable.negative;
      result.flutter_pairs = stable.flutter;
      compute_wrenches(model, data, options.time, 1.0);
      if (stable.negative > 0 || stable.flutter > 0) {
        result.ok = false;
        result.message = "the equilibrium found is unstable: ";
        if (stable.negative > 0)
          result.message += "its tangent stiffness has " + std::to_string(stable.negative) +
                            " direction(s) of negative stiffness (the structure buckles or "
                            "snaps under these loads, or the load path reached an unstable "
                            "branch)";
        if (stable.negative > 0 && stable.flutter > 0) result.message += "; ";
        if (stable.flutter > 0)
          result.message += std::to_string(stable.flutter) +
                            " pair(s) of its small vibrations grow (flutter: the loads without a "
                            "potential, torques of fixed direction or follower loads, feed them "
                            "energy)";
      }
    }
    if (result.ok && result.residual_norm > std::max(options.tolerance, 1e-6) * f_ref)
      result.warnings.push_back(
          format("rounding limits the balance of the forces to %.3g N (%.3g of the load): ",
                 result.residual_norm, result.residual_norm / std::max(f_ref, 1e-300)) +
          format("element forces (shear in very short segments) are uncertain by that much; the "
                 "displacements are converged (last correction %.2g of them)",
                 result.correction));
    // A mechanism's last factorized tangent may be its unloaded start's: a pendulum started
    // hanging converges in one Newton step, and its swing had no stiffness until its joint
    // carried the bob (it warned "1 direction(s) without stiffness", a chain of three on
    // spherical joints 9 where only its 3 spins are free). Its null directions are those of the
    // equilibrium, counted again there.
    if (result.ok && !newton.held && newton.last_singular > 0) {
      compute_tangent(model, data, options.time, false, 1.0);
      std::string why;
      if (newton.solver.factorize(model, data, &why))
        newton.last_singular = newton.solver.null_directions;
      compute_wrenches(model, data, options.time, 1.0);
    }
    if (!newton.held) result.singular_directions = newton.last_singular;
    // Directions the final tangent cannot tell from free ones take no part in the Newton
    // corrections, so corrections that vanish say nothing of them; where rounding also leaves
    // more than kMostUnbalancedShare of the load unbalanced, their displacements are not
    // resolved. studies/hinged_bob.json with its hinge's relative_compliance at 1e-8 (a penalty
    // 4e12 times the cantilever's stiffness) converged so with 0.75 of its load unbalanced: a tip
    // that did not sag (5.8e-16 m for 0.028 m), the hinge's force of the wrong sign, and a modal
    // analysis about that state, status ok (an adversarial review, 2026-12-01).
    if (result.ok && newton.last_singular > 0 &&
        result.residual_norm > kMostUnbalancedShare * f_ref) {
      result.ok = false;
      result.message =
          format("rounding leaves %.3g N of the forces unbalanced (%.3g of the load) along ",
                 result.residual_norm, result.residual_norm / f_ref) +
          std::to_string(newton.last_singular) +
          " direction(s) whose stiffness is below what the tangent resolves: the equilibrium is "
          "beyond double precision (a structure far softer than its joints' or rails' penalty: "
          "raise their relative_compliance)";
    }
    if (newton.reported_singular() > 0)
      result.warnings.push_back(
          newton.held
              ? "the tangent stiffness lost its stiffness in " + std::to_string(newton.singular) +
                    " direction(s) along the load path (a limit or bifurcation point of the "
                    "structure was passed); the equilibrium reached from it is reported"
              : "the tangent stiffness has " + std::to_string(newton.last_singular) +
                    " direction(s) without stiffness (a free mechanism); the equilibrium closest "
                    "to the initial configuration along them is reported");
    // What the beam law leaves out of the elements' own axial forces, measured on this
    // equilibrium (core/analysis/axial_force_check.hpp).
    if (result.ok && newton.reported_singular() == 0) {
      const MissingAxialForces missing(model, data);
      std::string why;
      if (missing.any()) {
        compute_tangent(model, data, options.time, false, 1.0);
        if (newton.solver.factorize(model, data, &why) && newton.solver.null_directions == 0) {
          const AxialForceEffect effect = static_axial_force_effect(
              model, data, missing,
              [&](const Eigen::VectorXd& b) { return newton.solver.solve(b); });
          if (std::string w = static_axial_force_warning(missing, effect); !w.empty())
            result.warnings.push_back(std::move(w));
        }
      }
    }
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
  result.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

}  // namespace beamrail
