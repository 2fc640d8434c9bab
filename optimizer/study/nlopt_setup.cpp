#include "optimizer/study/nlopt_setup.hpp"

#include <algorithm>
#include <chrono>

namespace beamrail {
namespace {

bool needs_gradient(const std::string& algorithm) {
  return algorithm.size() > 2 && algorithm[1] == 'D';
}

// Algorithms that take inequality constraints themselves.
bool handles_constraints(nlopt_algorithm a) {
  switch (a) {
    case NLOPT_LN_COBYLA:
    case NLOPT_LD_MMA:
    case NLOPT_LD_CCSAQ:
    case NLOPT_LD_SLSQP:
    case NLOPT_GN_ISRES:
    case NLOPT_GN_ORIG_DIRECT:
    case NLOPT_GN_ORIG_DIRECT_L:
    case NLOPT_GN_AGS:
    case NLOPT_AUGLAG:
    case NLOPT_LN_AUGLAG:
    case NLOPT_LD_AUGLAG:
      return true;
    default:
      return false;
  }
}

// The test problem of nlopt_refusal: a quadratic bowl inside the bounds, and constraints that hold
// near the middle of the box. Gradients are exact.
struct TestProblem {
  std::vector<double> middle, range;
  int evaluations = 0;
};

double test_objective(unsigned n, const double* x, double* grad, void* data) {
  auto* p = static_cast<TestProblem*>(data);
  ++p->evaluations;
  double f = 0.0;
  for (unsigned i = 0; i < n; ++i) {
    const double u = (x[i] - p->middle[i]) / p->range[i] - 0.2;
    f += u * u;
    if (grad) grad[i] = 2.0 * u / p->range[i];
  }
  return f;
}

double test_constraint(unsigned n, const double* x, double* grad, void* data) {
  auto* p = static_cast<TestProblem*>(data);
  double g = -0.25;
  for (unsigned i = 0; i < n; ++i) {
    const double u = (x[i] - p->middle[i]) / p->range[i];
    g += u * u;
    if (grad) grad[i] = 2.0 * u / p->range[i];
  }
  return g;
}

}  // namespace

bool runs_local_optimizer(nlopt_algorithm a) {
  switch (a) {
    case NLOPT_AUGLAG:
    case NLOPT_AUGLAG_EQ:
    case NLOPT_LN_AUGLAG:
    case NLOPT_LD_AUGLAG:
    case NLOPT_LN_AUGLAG_EQ:
    case NLOPT_LD_AUGLAG_EQ:
    case NLOPT_G_MLSL:
    case NLOPT_G_MLSL_LDS:
    case NLOPT_GN_MLSL:
    case NLOPT_GD_MLSL:
    case NLOPT_GN_MLSL_LDS:
    case NLOPT_GD_MLSL_LDS:
      return true;
    default:
      return false;
  }
}

double scaled_variable(const DesignVariable& v, double x) {
  return (x - v.lower) / (v.upper - v.lower);
}

double physical_variable(const DesignVariable& v, double s) {
  return std::clamp(v.lower + s * (v.upper - v.lower), v.lower, v.upper);
}

NloptSetup::NloptSetup(const OptimizePlan& plan, const std::vector<DesignVariable>& variables) {
  const unsigned n = static_cast<unsigned>(variables.size());
  const bool gradient = needs_gradient(plan.algorithm);
  // NLopt sees every variable scaled to [0, 1] by its bounds (scaled_variable).
  const std::vector<double> lower(n, 0.0), upper(n, 1.0);
  // An optimizer with the bounds and tolerances; `description` names it.
  const auto make = [&](nlopt_algorithm a) {
    nlopt_opt o = nlopt_create(a, n);
    nlopt_set_lower_bounds(o, lower.data());
    nlopt_set_upper_bounds(o, upper.data());
    nlopt_set_xtol_rel(o, plan.xtol_rel);
    nlopt_set_ftol_rel(o, plan.ftol_rel);
    return o;
  };
  const std::string local_name = !plan.local_algorithm.empty() ? plan.local_algorithm
                                 : gradient                    ? "LD_MMA"
                                                               : "LN_COBYLA";
  // The named algorithm with its local optimizer (NLopt copies the local one into it). NLopt
  // 2.7's own default subsidiary optimizer of LN_AUGLAG crashes: every wrapper is given one.
  const nlopt_algorithm algorithm = nlopt_algorithm_from_string(plan.algorithm.c_str());
  nlopt_opt main = make(algorithm);
  description_ = plan.algorithm;
  if (runs_local_optimizer(algorithm)) {
    nlopt_opt local = make(nlopt_algorithm_from_string(local_name.c_str()));
    nlopt_set_local_optimizer(main, local);
    nlopt_destroy(local);
    description_ += "(" + local_name + ")";
  }
  if (!plan.constraints.empty() && !handles_constraints(algorithm)) {
    // Algorithms without constraint support run inside an augmented Lagrangian.
    opt_ = make(gradient ? NLOPT_LD_AUGLAG : NLOPT_LN_AUGLAG);
    nlopt_set_local_optimizer(opt_, main);
    nlopt_destroy(main);
    description_ = std::string(gradient ? "LD_AUGLAG" : "LN_AUGLAG") + "(" + description_ + ")";
  } else {
    opt_ = main;
  }
}

NloptSetup::~NloptSetup() {
  if (opt_) nlopt_destroy(opt_);
}

std::string nlopt_refusal(const OptimizePlan& plan, const std::vector<DesignVariable>& variables) {
  TestProblem problem;
  problem.middle.assign(variables.size(), 0.5);  // in the scaled variables
  problem.range.assign(variables.size(), 1.0);
  const NloptSetup setup(plan, variables);
  nlopt_opt opt = setup.get();
  nlopt_set_min_objective(opt, test_objective, &problem);
  for (size_t j = 0; j < plan.constraints.size(); ++j)
    nlopt_add_inequality_constraint(opt, test_constraint, &problem, 1e-8);
  // Enough evaluations for the wrappers to start their local optimizers, where NLopt checks
  // them; the time limit only guards against an algorithm that ignores maxeval.
  nlopt_set_maxeval(opt, 200);
  nlopt_set_maxtime(opt, 2.0);
  std::vector<double> x = problem.middle;
  double f = 0.0;
  const nlopt_result result = nlopt_optimize(opt, x.data(), &f);
  if (result != NLOPT_INVALID_ARGS && result != NLOPT_OUT_OF_MEMORY) return "";
  const char* why = nlopt_get_errmsg(opt);
  std::string what = setup.description();
  if (!plan.constraints.empty())
    what += " with " + std::to_string(plan.constraints.size()) +
            (plan.constraints.size() == 1 ? " constraint" : " constraints");
  return "NLopt cannot run " + what + " (it returned " + nlopt_result_to_string(result) +
         (why ? std::string(": ") + why : std::string()) +
         (!why && problem.evaluations == 0 ? "; the installed NLopt may lack this algorithm" : "") +
         ")";
}

}  // namespace beamrail
