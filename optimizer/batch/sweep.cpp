#include "optimizer/batch/sweep.hpp"

#include <chrono>
#include <cmath>
#include <iostream>
#include <set>

#include "core/analysis/stop_request.hpp"
#include "optimizer/batch/executor.hpp"
#include "optimizer/batch/progress.hpp"
#include "optimizer/batch/sampling.hpp"
#include "optimizer/cli/interruption.hpp"
#include "optimizer/output/batch_table.hpp"
#include "optimizer/output/summary.hpp"
#include "optimizer/output/tables.hpp"
#include "optimizer/output/version.hpp"
#include "optimizer/run/designs.hpp"

namespace beamrail {

int run_sweep(const Study& study, const RunSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  const DesignStudy& plan = *study.design;
  const std::vector<Design> designs = sweep_designs(plan);
  const DesignEvaluator evaluator(study);
  if (!evaluator.setup_failure().empty())
    return fail_before_designs(study, settings.output, "sweep", evaluator.setup_failure());

  CsvRow header{"index"};
  for (const DesignVariable& v : plan.variables) header.push_back(v.name);
  for (const ResponseSpec& r : study.responses) header.push_back(r.name);
  for (const char* c : {"status", "warnings", "wall_s", "message"}) header.push_back(c);
  const size_t status_column = 1 + plan.variables.size() + study.responses.size();

  const std::filesystem::path samples = settings.output / "samples.csv";
  BatchTable table;
  std::vector<CsvRow> existing;
  std::string error;
  if (const int status =
          open_exit_status(table.open(samples, header, settings.resume, &existing, &error), error))
    return status;
  std::set<long> done;
  long failures = 0, warned = 0;
  for (const CsvRow& row : existing) {
    done.insert(std::strtol(row[0].c_str(), nullptr, 10));
    failures += row[status_column] != "ok";
    warned += std::strtol(row[status_column + 1].c_str(), nullptr, 10) > 0;
  }
  std::vector<long> todo;
  for (long i = 0; i < static_cast<long>(designs.size()); ++i)
    if (!done.count(i)) todo.push_back(i);

  Progress progress(static_cast<long>(designs.size()), settings.quiet);
  // The executor hands outcomes back one at a time: the counts need no lock.
  long finished = static_cast<long>(done.size()), failed = failures, evaluated = 0,
       with_warnings = warned;
  const std::unique_ptr<BatchExecutor> executor =
      make_executor(settings, static_cast<long>(todo.size()));
  std::vector<Design> batch;
  for (long i : todo) batch.push_back(designs[i]);
  executor->evaluate(evaluator, batch, [&](long n, const DesignOutcome& o) {
    if (o.status == Status::kInterrupted) return true;  // not a result: a resumed run evaluates it
    const long i = todo[n];
    CsvRow row{std::to_string(i)};
    for (double x : designs[i]) row.push_back(format_number(x));
    for (double r : o.responses) row.push_back(format_number(r));
    row.push_back(status_name(o.status));
    row.push_back(std::to_string(o.warnings));
    row.push_back(format_number(o.wall_seconds));
    row.push_back(o.message);
    // After a write error no design starts.
    if (!table.append(row)) return false;
    ++evaluated;
    if (o.warnings > 0) ++with_warnings;
    if (o.status != Status::kOk) ++failed;
    progress.update(++finished, failed, "");
    return true;
  });
  progress.finish();
  const int signal = stop_requested();
  const bool interrupted = signal != 0 && finished < static_cast<long>(designs.size());
  // Sorted into index order; after a write error the table keeps the rows written before it.
  const bool written = table.finalize({0}, &error);

  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  nlohmann::json s;
  s["study"] = study.name;
  s["file"] = study.file;
  s["beamrail_version"] = kVersion;
  s["type"] = "sweep";
  s["status"] = !written ? "failed" : interrupted ? "interrupted" : "ok";
  s["message"] = !written      ? error
                 : interrupted ? "interrupted by " + signal_name(signal) + " after " +
                                     std::to_string(finished) + " of " +
                                     std::to_string(designs.size()) + " designs"
                               : "";
  s["warnings"] = study.input_warnings;
  s["designs"] = designs.size();
  s["designs_in_table"] = finished;
  s["evaluated_now"] = evaluated;
  s["resumed_from_table"] = done.size();
  s["failed_or_invalid"] = failed;
  s["designs_with_warnings"] = with_warnings;
  s["ranks"] = executor->ranks();
  s["threads"] = executor->threads();
  const ExecutorStats stats = executor->stats();
  if (executor->ranks() > 1) {
    s["designs_per_rank"] = stats.designs_per_rank;
    s["scheduler_seconds"] = stats.scheduler_seconds;
    s["polling_seconds"] = stats.polling_seconds;
  }
  s["wall_seconds"] = wall;
  s["evaluations_per_second"] = wall > 0 ? static_cast<double>(evaluated) / wall : 0.0;
  s["model"] = model_summary(study.model);
  std::string summary_error;
  const bool summarized =
      write_file_atomically(settings.output / "summary.json", s.dump(2) + "\n", &summary_error);
  if (!written) {
    std::cerr << "beamrail: " << error << "\n";
    if (!summarized) std::cerr << "beamrail: " << summary_error << "\n";
    return 1;
  }
  if (!summarized) {
    std::cerr << "beamrail: " << summary_error << "\n";
    return 1;
  }
  if (interrupted) {
    std::cerr << "beamrail: " << study.name << " interrupted by " << signal_name(signal) << ": "
              << finished << " of " << designs.size() << " designs are in " << samples.string()
              << "; continue with: " << settings.command << " --resume\n";
    return interrupted_exit_status(signal);
  }
  std::cout << study.name << ": " << designs.size() << " designs (" << failed
            << " failed or invalid, " << with_warnings << " with warnings) in " << wall << " s -> "
            << settings.output.string() << "\n";
  return 0;
}

}  // namespace beamrail
