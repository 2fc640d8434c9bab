#include "optimizer/batch/optimization_problem.hpp"

#include <algorithm>
#include <cmath>

#include "optimizer/batch/sampling.hpp"

namespace beamrail {
namespace {

// A constraint of a reported design is "active" when its relative margin (the margin over |bound|,
// or the margin itself for a bound of 0) is within max(kActiveFloor, kActiveFactor * xtol_rel) of
// zero. NLopt stops once a step moves the scaled variables (in [0, 1]) by less than xtol_rel of
// their value; a constraint the optimum rests on is then met to about its sensitivity (relative
// change of the constraint per relative change of a variable: 1 for a frequency ~ d, 3 for a
// stress ~ 1/d^3) times that step. The factor 10 covers sensitivities up to 10; the floor covers
// the rounding of the responses (modal frequencies resolve to ~1e-8 and worse, see "Guarantees")
// and NLopt's own constraint tolerance (1e-8). summary.json and best.json give the tolerance used
// ("active_tolerance").
constexpr double kActiveFloor = 1e-6;
constexpr double kActiveFactor = 10.0;

}  // namespace

bool needs_gradient(const std::string& algorithm) {
  return algorithm.size() > 2 && algorithm[1] == 'D';
}

bool OptimizationProblem::exact_gradients() const {
  return needs_gradient(plan_.algorithm) && plan_.gradient == OptimizePlan::Gradient::kExact;
}

double OptimizationProblem::active_tolerance() const {
  return std::max(kActiveFloor, kActiveFactor * plan_.xtol_rel);
}

bool OptimizationProblem::usable(const DesignOutcome& o) const {
  return o.status == Status::kOk &&
         (o.warnings == 0 || plan_.warned_designs == OptimizePlan::WarnedDesigns::kAccept);
}

double OptimizationProblem::objective_of(const DesignOutcome& o) const {
  if (!usable(o)) return kPenalty;
  double f = 0.0;
  switch (plan_.goal) {
    case OptimizePlan::Goal::kMinimize:
      f = o.responses[plan_.response];
      break;
    case OptimizePlan::Goal::kMaximize:
      f = -o.responses[plan_.response];
      break;
    case OptimizePlan::Goal::kTarget:
      for (const auto& [k, t] : plan_.targets) {
        const double scale = t != 0.0 ? std::abs(t) : 1.0;
        f += std::pow((o.responses[k] - t) / scale, 2);
      }
      break;
  }
  return std::isfinite(f) ? f : kPenalty;
}

double OptimizationProblem::constraint_of(const DesignOutcome& o, int j) const {
  const Constraint& c = plan_.constraints[j];
  const double r = o.responses[c.response];
  if (!usable(o) || !std::isfinite(r)) return kPenalty;
  const double scale = c.bound != 0.0 ? std::abs(c.bound) : 1.0;
  switch (c.kind) {
    case Constraint::Kind::kAtLeast:
      return (c.bound - r) / scale;
    case Constraint::Kind::kAtMost:
      return (r - c.bound) / scale;
    default:
      return (std::abs(r) - c.bound) / scale;
  }
}

bool OptimizationProblem::feasible(const DesignOutcome& o) const {
  if (!usable(o) || objective_of(o) >= kPenalty) return false;
  for (size_t j = 0; j < plan_.constraints.size(); ++j)
    if (!(constraint_of(o, static_cast<int>(j)) <= kFeasibility)) return false;
  return true;
}

double OptimizationProblem::value_of(const DesignOutcome& o, int which) const {
  return which < 0 ? objective_of(o) : constraint_of(o, which);
}

bool OptimizationProblem::partials_of(const DesignOutcome& o, int which, Eigen::VectorXd& d) const {
  if (value_of(o, which) >= kPenalty) return false;
  d = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(study_.responses.size()));
  if (which < 0) {
    switch (plan_.goal) {
      case OptimizePlan::Goal::kMinimize:
        d(plan_.response) = 1.0;
        break;
      case OptimizePlan::Goal::kMaximize:
        d(plan_.response) = -1.0;
        break;
      case OptimizePlan::Goal::kTarget:
        for (const auto& [k, t] : plan_.targets) {
          const double scale = t != 0.0 ? std::abs(t) : 1.0;
          d(k) += 2.0 * (o.responses[k] - t) / (scale * scale);
        }
        break;
    }
    return true;
  }
  const Constraint& c = plan_.constraints[which];
  const double scale = c.bound != 0.0 ? std::abs(c.bound) : 1.0;  // as constraint_of
  const double r = o.responses[c.response];
  d(c.response) = c.kind == Constraint::Kind::kAtLeast  ? -1.0 / scale
                  : c.kind == Constraint::Kind::kAtMost ? 1.0 / scale
                                                        : (r < 0.0 ? -1.0 : 1.0) / scale;
  return true;
}

std::vector<Design> OptimizationProblem::start_points() const {
  std::vector<Design> points;
  bool all_initial = true;
  Design initial;
  for (const DesignVariable& v : variables_) {
    all_initial = all_initial && v.initial.has_value();
    initial.push_back(v.initial.value_or(0.5 * (v.lower + v.upper)));
  }
  if (all_initial) points.push_back(initial);
  const int more = plan_.starts - static_cast<int>(points.size());
  if (more > 0)
    for (Design& d : latin_hypercube(variables_, more, plan_.seed)) points.push_back(d);
  return points;
}

}  // namespace beamrail
