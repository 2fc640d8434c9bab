#include "optimizer/batch/sweep.hpp"

#include <chrono>

#include "optimizer/batch/progress.hpp"
#include "optimizer/batch/sampling.hpp"
#include "optimizer/run/designs.hpp"

namespace beamrail {

SweepRun sweep(const Study& study, const DesignEvaluator& evaluator, const RunSettings& settings,
               const std::set<long>& done, long shown_failed,
               const std::function<bool(long, const Design&, const DesignOutcome&)>& row) {
  const auto start = std::chrono::steady_clock::now();
  const std::vector<Design> designs = sweep_designs(*study.design);
  SweepRun run;
  run.designs = static_cast<long>(designs.size());
  std::vector<long> todo;
  for (long i = 0; i < run.designs; ++i)
    if (!done.count(i)) todo.push_back(i);

  Progress progress(run.designs, settings.quiet);
  // The executor hands outcomes back one at a time: the counts need no lock.
  long finished = static_cast<long>(done.size()), failed = shown_failed;
  const std::unique_ptr<BatchExecutor> executor =
      make_executor(settings, static_cast<long>(todo.size()));
  std::vector<Design> batch;
  for (long i : todo) batch.push_back(designs[i]);
  executor->evaluate(evaluator, batch, [&](long n, const DesignOutcome& o) {
    if (o.status == Status::kInterrupted) return true;  // not a result: a resumed run evaluates it
    const long i = todo[n];
    // After a write error no design starts.
    if (!row(i, designs[i], o)) return false;
    ++run.evaluated;
    if (o.warnings > 0) ++run.with_warnings;
    if (o.status != Status::kOk) ++run.failed, ++failed;
    progress.update(++finished, failed, "");
    return true;
  });
  progress.finish();
  run.ranks = executor->ranks();
  run.threads = executor->threads();
  run.stats = executor->stats();
  run.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

}  // namespace beamrail
