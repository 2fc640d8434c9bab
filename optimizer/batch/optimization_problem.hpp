// What an optimization minimizes and bounds, as functions of a design's outcome: the objective
// (minimize, maximize, or least-squares targets) and the inequality constraints on responses,
// with the penalty NLopt sees for a design that failed. Computing only: no files, no printing.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "optimizer/batch/sampling.hpp"
#include "optimizer/run/designs.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {

// Objective and constraint values given to NLopt for a design that failed or is invalid.
inline constexpr double kPenalty = 1e30;
// A constraint counts as met up to this fraction of its bound.
inline constexpr double kFeasibility = 1e-9;

// Whether the NLopt algorithm named uses gradients ("LD_MMA", "GD_STOGO").
bool needs_gradient(const std::string& algorithm);

class OptimizationProblem {
 public:
  explicit OptimizationProblem(const Study& study)
      : study_(study), plan_(study.design->optimize), variables_(study.design->variables) {}

  const Study& study() const { return study_; }
  const OptimizePlan& plan() const { return plan_; }
  const std::vector<DesignVariable>& variables() const { return variables_; }

  // An evaluated design the optimization may use: ok, and without warnings unless they are
  // accepted ("warned_designs").
  bool usable(const DesignOutcome& o) const;
  // The objective to minimize (kPenalty when not usable or not finite).
  double objective_of(const DesignOutcome& o) const;
  // Constraint j relative to |bound| (or 1 for a bound of 0), <= 0 when met; kPenalty when the
  // design is not usable.
  double constraint_of(const DesignOutcome& o, int j) const;
  bool feasible(const DesignOutcome& o) const;
  // which = -1 the objective, j >= 0 constraint j.
  double value_of(const DesignOutcome& o, int which) const;
  // d value_of / d responses; false when there is none (a penalty).
  bool partials_of(const DesignOutcome& o, int which, Eigen::VectorXd& d) const;

  // Whether NLopt's gradients are the design sensitivities.
  bool exact_gradients() const;
  // A constraint of a reported design is "active" when its relative margin is within this of 0.
  double active_tolerance() const;

  // The starts' designs: the variables' initial values (when every variable has one), then
  // Latin-hypercube points up to `starts`.
  std::vector<Design> start_points() const;

 private:
  const Study& study_;
  const OptimizePlan& plan_;
  const std::vector<DesignVariable>& variables_;
};

}  // namespace beamrail
