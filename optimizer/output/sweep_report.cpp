#include "optimizer/output/sweep_report.hpp"

#include <cstdlib>

#include "core/analysis/stop_request.hpp"
#include "optimizer/output/summary.hpp"
#include "optimizer/output/tables.hpp"
#include "optimizer/output/version.hpp"
#include "optimizer/run/status.hpp"

namespace beamrail {

SweepTable::SweepTable(const Study& study, const RunSettings& settings)
    : study_(study), settings_(settings) {}

std::filesystem::path SweepTable::path() const { return settings_.output / "samples.csv"; }

BatchTable::Opened SweepTable::open() {
  const DesignStudy& plan = *study_.design;
  CsvRow header{"index"};
  for (const DesignVariable& v : plan.variables) header.push_back(v.name);
  for (const ResponseSpec& r : study_.responses) header.push_back(r.name);
  for (const char* c : {"status", "warnings", "wall_s", "message"}) header.push_back(c);
  const size_t status_column = 1 + plan.variables.size() + study_.responses.size();
  std::vector<CsvRow> existing;
  const BatchTable::Opened opened =
      table_.open(path(), header, settings_.resume, &existing, &error_);
  if (opened != BatchTable::Opened::kOk) return opened;
  for (const CsvRow& row : existing) {
    resumed_.insert(std::strtol(row[0].c_str(), nullptr, 10));
    resumed_failed_ += row[status_column] != status_name(Status::kOk);
    resumed_warned_ += std::strtol(row[status_column + 1].c_str(), nullptr, 10) > 0;
  }
  return BatchTable::Opened::kOk;
}

bool SweepTable::append(long index, const Design& x, const DesignOutcome& o) {
  CsvRow row{std::to_string(index)};
  for (double v : x) row.push_back(format_number(v));
  for (double r : o.responses) row.push_back(format_number(r));
  row.push_back(status_name(o.status));
  row.push_back(std::to_string(o.warnings));
  row.push_back(format_number(o.wall_seconds));
  row.push_back(o.message);
  return table_.append(row);
}

bool SweepTable::finalize() { return table_.finalize({0}, &error_); }

SweepReport report_sweep(const Study& study, const RunSettings& settings, const SweepTable& table,
                         const SweepRun& run, bool written) {
  SweepReport report;
  report.finished = static_cast<long>(table.resumed().size()) + run.evaluated;
  report.failed = table.resumed_failed() + run.failed;
  report.with_warnings = table.resumed_warned() + run.with_warnings;
  const int signal = stop_requested();
  const bool interrupted = signal != 0 && report.finished < run.designs;
  const double wall = run.wall_seconds;
  nlohmann::json s;
  s["study"] = study.name;
  s["file"] = study.file;
  s["beamrail_version"] = kVersion;
  s["type"] = "sweep";
  s["status"] = run_status_name(!written      ? RunStatus::kFailed
                                : interrupted ? RunStatus::kInterrupted
                                              : RunStatus::kOk);
  const std::string message = !written      ? table.error()
                              : interrupted ? "interrupted by " + signal_name(signal) + " after " +
                                                  std::to_string(report.finished) + " of " +
                                                  std::to_string(run.designs) + " designs"
                                            : "";
  s["message"] = message;
  s["warnings"] = study.input_warnings;
  s["designs"] = run.designs;
  s["designs_in_table"] = report.finished;
  s["evaluated_now"] = run.evaluated;
  s["resumed_from_table"] = table.resumed().size();
  s["failed_or_invalid"] = report.failed;
  s["designs_with_warnings"] = report.with_warnings;
  s["ranks"] = run.ranks;
  s["threads"] = run.threads;
  if (run.ranks > 1) {
    s["designs_per_rank"] = run.stats.designs_per_rank;
    s["scheduler_seconds"] = run.stats.scheduler_seconds;
    s["polling_seconds"] = run.stats.polling_seconds;
  }
  s["wall_seconds"] = wall;
  s["evaluations_per_second"] = wall > 0 ? static_cast<double>(run.evaluated) / wall : 0.0;
  s["model"] = model_summary(study.model);
  RunOutcome& outcome = report.outcome;
  if (!written) outcome.errors.push_back(table.error());
  std::string summary_error;
  if (!write_file_atomically(settings.output / "summary.json", s.dump(2) + "\n", &summary_error))
    outcome.errors.push_back(summary_error);
  if (!outcome.errors.empty()) {
    outcome.kind = RunOutcome::Kind::kWriteError;
  } else if (interrupted) {
    outcome.kind = RunOutcome::Kind::kInterrupted;
    outcome.signal = signal;
    outcome.message = message;
  }
  return report;
}

}  // namespace beamrail
