#include "optimizer/batch/executor.hpp"

#include <cmath>
#include <exception>
#include <mutex>

#include "core/analysis/stop_request.hpp"
#include "optimizer/batch/mpi_job.hpp"

namespace beamrail {

namespace {

// The outcome of a design whose evaluation threw.
DesignOutcome thrown(const DesignEvaluator& evaluator, const std::string& message) {
  DesignOutcome o;
  o.status = Status::kFailed;
  o.message = message;
  o.responses.assign(evaluator.study().responses.size(), std::nan(""));
  return o;
}

}  // namespace

DesignOutcome evaluate_design(const DesignEvaluator& evaluator, const Design& x) {
  try {
    return evaluator.evaluate(x);
  } catch (const std::exception& e) {
    return thrown(evaluator, std::string("the evaluation threw: ") + e.what());
  } catch (...) {
    return thrown(evaluator, std::string("the evaluation threw: ") + kUnknownException);
  }
}

void ThreadExecutor::evaluate(const DesignEvaluator& evaluator, const std::vector<Design>& designs,
                              const DesignDone& done) {
  std::mutex mutex;
  bool stopped = false;
  const long n = static_cast<long>(designs.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads_)
  for (long i = 0; i < n; ++i) {
    if (stop_requested()) continue;
    {
      const std::lock_guard<std::mutex> lock(mutex);
      if (stopped) continue;
    }
    const DesignOutcome o = evaluate_design(evaluator, designs[i]);
    const std::lock_guard<std::mutex> lock(mutex);
    ++stats_.designs_per_rank[0];
    if (!done(i, o)) stopped = true;
  }
}

std::unique_ptr<BatchExecutor> make_executor(const RunSettings& settings, long work) {
  if (MpiJob* job = mpi_job(); job && job->size() > 1)
    return job->executor(settings.threads > 0 ? settings.threads : 1);
  return std::make_unique<ThreadExecutor>(batch_threads(settings, work));
}

}  // namespace beamrail
