#include "optimizer/batch/optimize.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>

#include "core/analysis/stop_request.hpp"
#include "optimizer/batch/executor.hpp"
#include "optimizer/batch/mpi_job.hpp"
#include "optimizer/batch/progress.hpp"
#include "optimizer/batch/start_task.hpp"

namespace beamrail {
namespace {

// Takes the rows and derivatives of every start (one call at a time), keeps the rows for the
// report, passes both on to the sink that writes them, and shows the progress line.
class Collector : public StartSink {
 public:
  Collector(const OptimizationProblem& problem, StartSink& out, Progress& progress,
            std::atomic<bool>& cancel, long budget)
      : problem_(problem), out_(out), progress_(progress), cancel_(cancel), budget_(budget) {}

  void record(const OptimizationRecord& r) override {
    const std::lock_guard<std::mutex> lock(mutex_);
    out_.record(r);
    if (!out_.good()) cancel_ = true;
    if (r.outcome.status != Status::kOk) ++failed_;
    if (r.feasible && r.objective < best_objective_) {
      best_objective_ = r.objective;
      best_text_ = best_text(r);
    }
    records_.push_back(r);
    progress_.update(static_cast<long>(records_.size()), failed_, best_text_);
  }
  void derivatives(const Design& x, const Eigen::MatrixXd& jacobian) override {
    const std::lock_guard<std::mutex> lock(mutex_);
    out_.derivatives(x, jacobian);
    if (!out_.good()) cancel_ = true;
  }
  bool good() const override { return out_.good(); }

  // A start is done: the progress total keeps only the designs it took of its budget.
  void finished(const StartResult& r) {
    const std::lock_guard<std::mutex> lock(mutex_);
    budget_ -= problem_.plan().max_evaluations - r.designs;
    progress_.set_total(budget_);
  }

  std::vector<OptimizationRecord> take_records() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return std::move(records_);
  }

 private:
  // What the progress line shows of a feasible record: "mass 16.32" (the objective's response)
  // or "objective 0.0012" (a target).
  std::string best_text(const OptimizationRecord& r) const {
    const OptimizePlan& plan = problem_.plan();
    char buf[32];
    const bool response = plan.goal != OptimizePlan::Goal::kTarget;
    std::snprintf(buf, sizeof buf, "%.6g",
                  response ? r.outcome.responses[plan.response] : r.objective);
    return (response ? problem_.study().responses[plan.response].name : std::string("objective")) +
           " " + buf;
  }

  const OptimizationProblem& problem_;
  StartSink& out_;
  Progress& progress_;
  std::atomic<bool>& cancel_;
  long budget_;
  std::mutex mutex_;
  std::vector<OptimizationRecord> records_;
  long failed_ = 0;
  double best_objective_ = kPenalty;
  std::string best_text_;
};

// The scale of each constraint: given, or |bound|, or for a bound of 0 the response's magnitude
// at the first start's design (`first`, nullptr when it has none).
std::vector<double> constraint_scales(const OptimizePlan& plan, const DesignOutcome* first) {
  std::vector<double> scales;
  for (const Constraint& c : plan.constraints) {
    double scale = std::abs(c.bound);
    if (c.scale) {
      scale = *c.scale;
    } else if (c.bound == 0.0) {
      const bool has = first && first->status != Status::kInterrupted &&
                       static_cast<size_t>(c.response) < first->responses.size();
      const double r = has ? std::abs(first->responses[c.response]) : 0.0;
      scale = std::isfinite(r) && r > 0.0 ? r : 1.0;
    }
    scales.push_back(scale);
  }
  return scales;
}

// A start that never ran (the batch stopped first): stopped by beamrail before its first design.
StartResult not_run(const OptimizationProblem& problem, int index) {
  StartResult r;
  r.index = index;
  r.result = NLOPT_FORCED_STOP;
  r.stopped = true;
  r.objective_scale = problem.plan().objective_scale.value_or(1.0);
  return r;
}

}  // namespace

OptimizationRun optimize(const OptimizationProblem& problem, const DesignEvaluator& evaluator,
                         const RunSettings& settings, const std::vector<ResumedRow>& resumed,
                         const std::vector<std::pair<Design, Eigen::MatrixXd>>& derivatives,
                         StartSink& out) {
  const auto wall_start = std::chrono::steady_clock::now();
  const OptimizePlan& plan = problem.plan();
  OptimizationRun run;
  // Earlier evaluations become the cache that NLopt's replayed path hits.
  DesignCache cache;
  for (const ResumedRow& r : resumed) cache.add(r.x, r.outcome);
  for (const auto& [x, jacobian] : derivatives)
    cache.set_jacobian(x, std::make_shared<const Eigen::MatrixXd>(jacobian));

  const std::vector<Design> points = problem.start_points();
  const int n_starts = static_cast<int>(points.size());
  MpiJob* job = mpi_job();
  const bool spread = job && job->size() > 1;
  // Designs evaluated at once in one process: the starts, the central-difference points of one
  // gradient, or the variables whose derivatives one design's sensitivities compute in parallel.
  // Under mpirun each rank runs one start at a time with -j threads (default 1).
  const long n_variables = static_cast<long>(problem.variables().size());
  const long at_once =
      std::max(static_cast<long>(n_starts), !needs_gradient(plan.algorithm) ? 1
                                            : problem.exact_gradients()     ? n_variables
                                                                            : 2 * n_variables + 1);
  run.ranks = spread ? job->size() : 1;
  // Under mpirun the ranks run whole starts, or with fewer starts than ranks and difference
  // gradients, the points of each gradient.
  const bool by_designs = spread && n_starts < job->size() && needs_gradient(plan.algorithm) &&
                          !problem.exact_gradients();
  run.threads =
      spread ? (settings.threads > 0 ? settings.threads : 1) : batch_threads(settings, at_once);
  omp_set_num_threads(run.threads);  // the sensitivities' parallel loops
  const long budget = static_cast<long>(plan.max_evaluations) * n_starts;
  Progress progress(budget, settings.quiet);
  std::atomic<bool> cancel(false);
  Collector collector(problem, out, progress, cancel, budget);

  // The first start's design, evaluated now: the constraints' scales may come from it.
  std::optional<DesignOutcome> first;
  if (n_starts > 0 && !stop_requested())
    first = evaluate_into_cache(problem, evaluator, points[0], cache, collector, &run.cost);
  run.constraint_scales = constraint_scales(plan, first ? &*first : nullptr);
  std::vector<StartTask> tasks;
  for (int s = 0; s < n_starts; ++s)
    tasks.push_back(StartTask{s + 1, points[s], run.constraint_scales});

  run.starts.resize(tasks.size());
  if (!spread) {
    // Starts side by side on the threads, sharing the cache; one start alone gets the threads
    // for its gradients' points.
#pragma omp parallel for schedule(dynamic, 1) if (n_starts > 1) \
    num_threads(std::min(run.threads, std::max(1, n_starts)))
    for (int s = 0; s < n_starts; ++s) {
      run.starts[s] =
          run_start(problem, evaluator, tasks[s], cache, run.threads, collector, cancel);
      collector.finished(run.starts[s]);
    }
  } else if (by_designs) {
    // Fewer starts than ranks, each call of NLopt asking for the points of a difference gradient:
    // the starts run one after another here, and the designs of each call go to the ranks.
    const std::unique_ptr<BatchExecutor> designs = job->executor(run.threads);
    for (int s = 0; s < n_starts; ++s) {
      run.starts[s] = run_start(problem, evaluator, tasks[s], cache, run.threads, collector, cancel,
                                designs.get());
      collector.finished(run.starts[s]);
    }
    run.designs_per_rank = designs->stats().designs_per_rank;
    run.scheduler_seconds = designs->stats().scheduler_seconds;
  } else {
    // Each start goes whole to a rank with the designs it may replay: its rows of history.csv,
    // and the first start the design evaluated above.
    std::vector<std::vector<KnownDesign>> known(tasks.size());
    for (const ResumedRow& r : resumed)
      if (r.start >= 1 && r.start <= n_starts)
        known[r.start - 1].push_back({r.x, r.outcome, false, nullptr});
    if (first && first->status != Status::kInterrupted && n_starts > 0)
      known[0].push_back({points[0], *first, false, nullptr});
    std::vector<std::vector<char>> packed;
    for (size_t s = 0; s < tasks.size(); ++s) {
      for (KnownDesign& k : known[s]) k.has_jacobian = cache.find_jacobian(k.x, &k.jacobian);
      packed.push_back(pack_start_task(tasks[s], known[s]));
    }
    run.starts_per_rank.assign(job->size(), 0);
    TaskCallbacks callbacks;
    callbacks.run_here = [&](const std::vector<char>& task,
                             const std::function<void(std::vector<char>)>& send,
                             const std::atomic<bool>& stop) {
      return run_start_task(evaluator, run.threads, task, send, stop);
    };
    callbacks.message = [&](long, const std::vector<char>& message) {
      unpack_start_message(message, collector);
      return !cancel;
    };
    callbacks.finished = [&](long task, int rank, const std::vector<char>& result) {
      StartResult& r = run.starts[task];
      r = unpack_start_result(result);
      r.index = static_cast<int>(task) + 1;
      r.rank = rank;
      ++run.starts_per_rank[rank];
      collector.finished(r);
      return !cancel;
    };
    const std::vector<bool> ran = job->run_tasks(evaluator.study(), run.threads,
                                                 TaskKind::kOptimizationStart, packed, callbacks);
    for (size_t s = 0; s < tasks.size(); ++s)
      if (!ran[s]) run.starts[s] = not_run(problem, static_cast<int>(s) + 1);
  }
  progress.finish();
  for (const StartResult& r : run.starts) run.cost.add(r.cost);
  run.records = collector.take_records();
  std::sort(run.records.begin(), run.records.end(),
            [](const OptimizationRecord& a, const OptimizationRecord& b) {
              return std::tie(a.start, a.evaluation) < std::tie(b.start, b.evaluation);
            });
  run.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return run;
}

}  // namespace beamrail
