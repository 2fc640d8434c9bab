// The NLopt optimizer an optimization plan runs: the named algorithm with its bounds and
// tolerances; a local optimizer for the algorithms that run one (AUGLAG and MLSL in all their
// variants: `local_algorithm`, default LD_MMA for gradient algorithms and LN_COBYLA otherwise);
// wrapped in an augmented Lagrangian (LN_AUGLAG or LD_AUGLAG) when the study has constraints the
// algorithm cannot take. Whether NLopt accepts the combination is checked when the study is read,
// by running it on a small test problem: NLopt reports some refusals only after its first
// evaluations (and the installed NLopt may lack an algorithm), and a refusal found during the run
// would waste the study.
#pragma once

#include <nlopt.h>

#include <string>
#include <vector>

#include "optimizer/study/design_study.hpp"

namespace beamrail {

class NloptSetup {
 public:
  NloptSetup(const OptimizePlan& plan, const std::vector<DesignVariable>& variables);
  ~NloptSetup();
  NloptSetup(const NloptSetup&) = delete;
  NloptSetup& operator=(const NloptSetup&) = delete;

  // The optimizer to give the objective, the constraints and the stopping criteria.
  nlopt_opt get() const { return opt_; }
  // What runs, e.g. "LN_AUGLAG(G_MLSL_LDS(LN_COBYLA))".
  const std::string& description() const { return description_; }

 private:
  nlopt_opt opt_ = nullptr;
  std::vector<nlopt_opt> owned_;
  std::string description_;
};

// NLopt works on the variables scaled to [0, 1] by their bounds, s = (x - lower) / (upper - lower),
// so that a diameter in metres and a position in metres or a modulus in pascals weigh alike in its
// steps, tolerances (xtol_rel applies to s) and quasi-Newton models.
double scaled_variable(const DesignVariable& v, double x);
double physical_variable(const DesignVariable& v, double s);  // clamped to the bounds

// Whether `algorithm` runs a local optimizer of its own (AUGLAG and MLSL variants).
bool runs_local_optimizer(nlopt_algorithm algorithm);

// Runs the plan's optimizer (its constraints with stand-ins) on a quadratic test problem within
// the variables' bounds. Returns "" when NLopt accepts it, else the reason it refused.
std::string nlopt_refusal(const OptimizePlan& plan, const std::vector<DesignVariable>& variables);

}  // namespace beamrail
