// Design studies (docs/study_files.md "study"): design variables addressing numbers of the study
// file by JSON pointer, sweeps over them, and NLopt optimization of the responses.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/analysis/transient.hpp"
#include "core/scene/json_reader.hpp"

namespace beamrail {

struct DesignVariable {
  std::string name;
  std::vector<std::string> pointers;  // RFC 6901, into the study document (scene inlined)
  // The number written at pointers[i] is factors[i] * value + offsets[i] (an affine link: a mass
  // m0 + k s following a width s).
  std::vector<double> factors, offsets;
  std::vector<double> values;  // sweep/grid: explicit values
  double lower = 0.0, upper = 0.0;
  int count = 0;                  // sweep/grid: lower..upper in count steps (when values is empty)
  std::optional<double> initial;  // optimize: first start's value
  double value = 0.0;             // sensitivity: the value differentiated at
  Where where;
};

struct SweepPlan {
  enum class Sampling { kGrid, kList, kLhs };
  Sampling sampling = Sampling::kGrid;
  std::vector<std::vector<double>> rows;  // list: explicit designs
  int samples = 0;                        // lhs
  unsigned long seed = 1;                 // lhs
};

struct Constraint {
  enum class Kind { kAtLeast, kAtMost, kAbsAtMost };  // ">=", "<=", "abs<="
  int response = 0;                                   // index into study.responses
  Kind kind = Kind::kAtLeast;
  double bound = 0.0;
  // NLopt sees (value - bound) / scale (signed so that <= 0 is met): given, or |bound|, or for a
  // bound of 0 the constraint's magnitude at the first start's design (1 when that is 0 too).
  std::optional<double> scale;
};

struct OptimizePlan {
  enum class Goal { kMinimize, kMaximize, kTarget };
  Goal goal = Goal::kMinimize;
  int response = 0;                             // minimize/maximize
  std::vector<std::pair<int, double>> targets;  // target: (response, value)
  std::vector<Constraint> constraints;
  std::string algorithm = "LN_COBYLA";  // any NLopt name
  std::string local_algorithm;          // for AUGLAG/MLSL wrappers (default chosen)
  int max_evaluations = 200;            // per start
  double xtol_rel = 1e-6, ftol_rel = 0.0, max_seconds = 0.0;
  int starts = 1;
  unsigned long seed = 1;
  // Gradients of LD_ algorithms: the exact design sensitivities (optimizer/run/sensitivities.hpp;
  // central differences for a design that has none, with a warning), or central differences.
  enum class Gradient { kExact, kDifferences };
  Gradient gradient = Gradient::kExact;
  double gradient_step = 1e-6;  // central differences: h = step * (upper - lower)
  // NLopt sees the objective divided by this: given, or |objective| at each start's first design.
  std::optional<double> objective_scale;
  // A design whose analyses gave warnings (the model's assumptions strained: large element
  // rotations, a rail at its min_length, ...): counted as infeasible (as a failed design: the
  // optimizer sees the penalty, and it is never the best) or accepted like any other.
  enum class WarnedDesigns { kInfeasible, kAccept };
  WarnedDesigns warned_designs = WarnedDesigns::kInfeasible;
};

// The name of a "warned_designs" choice in the study file and summary.json: "infeasible",
// "accept".
inline const char* warned_designs_name(OptimizePlan::WarnedDesigns choice) {
  return choice == OptimizePlan::WarnedDesigns::kAccept ? "accept" : "infeasible";
}

// The measured speed-accuracy trade of the study's transient analysis: every method at every
// tolerance against a tight reference run.
struct WorkPrecisionPlan {
  struct Method {
    std::string label;  // as shown in the table, e.g. "dirk ARK548L2SA_DIRK_8_4_5"
    IntegratorOptions integrator;
  };
  std::vector<Method> methods;
  std::vector<double> rtols;
  double atol_scale = 1e-4;     // atol = atol_scale * rtol
  IntegratorOptions reference;  // default: bdf at rtol 1e-11, atol 1e-12
  double max_seconds = 60.0;    // budget per run; a slower run is a timeout row
  double target_error = 1e-6;   // the cheapest run meeting it is named in the summary
};

// The derivatives of every response with respect to every variable at the study's own design
// (optimizer/run/sensitivities.hpp); with `check`, beside central differences of the responses.
struct SensitivityPlan {
  bool check = false;
  double check_step = 1e-5;  // relative step of the differences (of |value|, or 1 at 0)
};

struct DesignStudy {
  enum class Type { kSweep, kOptimize, kWorkPrecision, kSensitivity };
  Type type = Type::kSweep;
  std::vector<DesignVariable> variables;
  SweepPlan sweep;
  OptimizePlan optimize;
  WorkPrecisionPlan work_precision;
  SensitivityPlan sensitivity;
  // Wall-clock budget of one design's evaluation [s]; 0: none. A design still running when it is
  // spent becomes a "timeout" row.
  double max_seconds_per_design = 0.0;
};

}  // namespace beamrail
