#include "optimizer/batch/sensitivity_study.hpp"

#include <omp.h>

#include <chrono>
#include <cmath>
#include <memory>

#include "optimizer/batch/executor.hpp"

namespace beamrail {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

SensitivityResult compute_sensitivities(const Study& study, const DesignEvaluator& evaluator,
                                        const RunSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  const DesignStudy& plan = *study.design;
  SensitivityResult r;
  for (const DesignVariable& v : plan.variables) r.x.push_back(v.value);
  // The variables' derivatives are computed in parallel.
  r.threads = batch_threads(settings, static_cast<long>(r.x.size()));
  omp_set_num_threads(r.threads);
  r.design = evaluator.evaluate(r.x, &r.derivatives);
  r.design_seconds = seconds_since(start);

  // The check: each variable's central difference of the responses, every design evaluated (on
  // the executor's threads, or under mpirun on every rank).
  const size_t nr = study.responses.size(), nv = r.x.size();
  r.differences.assign(nr, std::vector<double>(nv, NAN));
  const auto check_start = std::chrono::steady_clock::now();
  if (plan.sensitivity.check && r.design.status == Status::kOk) {
    std::vector<Design> designs;  // per variable, the design up and the design down
    std::vector<double> steps;
    for (size_t j = 0; j < nv; ++j) {
      const double step = plan.sensitivity.check_step * (r.x[j] != 0.0 ? std::abs(r.x[j]) : 1.0);
      std::vector<double> up = r.x, down = r.x;
      up[j] += step;
      down[j] -= step;
      designs.push_back(std::move(up));
      designs.push_back(std::move(down));
      steps.push_back(step);
    }
    const std::unique_ptr<BatchExecutor> executor =
        make_executor(settings, static_cast<long>(designs.size()));
    std::vector<DesignOutcome> outcomes(designs.size());
    executor->evaluate(evaluator, designs, [&](long n, const DesignOutcome& o) {
      outcomes[static_cast<size_t>(n)] = o;
      return true;
    });
    r.ranks = executor->ranks();
    for (size_t j = 0; j < nv; ++j) {
      const DesignOutcome &u = outcomes[2 * j], &d = outcomes[2 * j + 1];
      if (u.status != Status::kOk || d.status != Status::kOk) {
        r.check_failure =
            "the check's design along \"" + plan.variables[j].name +
            "\" did not evaluate: " + (u.status != Status::kOk ? u.message : d.message);
        continue;
      }
      for (size_t k = 0; k < nr; ++k)
        r.differences[k][j] = (u.responses[k] - d.responses[k]) / (2.0 * steps[j]);
    }
  }
  r.check_seconds = seconds_since(check_start);
  return r;
}

}  // namespace beamrail
