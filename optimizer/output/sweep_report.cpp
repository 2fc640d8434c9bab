#include "optimizer/output/sweep_report.hpp"

#include <cstdlib>
#include <iostream>

#include "core/analysis/stop_request.hpp"
#include "optimizer/cli/interruption.hpp"
#include "optimizer/output/summary.hpp"
#include "optimizer/output/tables.hpp"
#include "optimizer/output/version.hpp"
#include "optimizer/run/status.hpp"

namespace beamrail {

SweepTable::SweepTable(const Study& study, const RunSettings& settings)
    : study_(study), settings_(settings) {}

std::filesystem::path SweepTable::path() const { return settings_.output / "samples.csv"; }

int SweepTable::open() {
  const DesignStudy& plan = *study_.design;
  CsvRow header{"index"};
  for (const DesignVariable& v : plan.variables) header.push_back(v.name);
  for (const ResponseSpec& r : study_.responses) header.push_back(r.name);
  for (const char* c : {"status", "warnings", "wall_s", "message"}) header.push_back(c);
  const size_t status_column = 1 + plan.variables.size() + study_.responses.size();
  std::vector<CsvRow> existing;
  if (const int status = open_exit_status(
          table_.open(path(), header, settings_.resume, &existing, &error_), error_))
    return status;
  for (const CsvRow& row : existing) {
    resumed_.insert(std::strtol(row[0].c_str(), nullptr, 10));
    resumed_failed_ += row[status_column] != status_name(Status::kOk);
    resumed_warned_ += std::strtol(row[status_column + 1].c_str(), nullptr, 10) > 0;
  }
  return 0;
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

int report_sweep(const Study& study, const RunSettings& settings, const SweepTable& table,
                 const SweepRun& run, bool written) {
  const long finished = static_cast<long>(table.resumed().size()) + run.evaluated;
  const long failed = table.resumed_failed() + run.failed;
  const long with_warnings = table.resumed_warned() + run.with_warnings;
  const int signal = stop_requested();
  const bool interrupted = signal != 0 && finished < run.designs;
  const double wall = run.wall_seconds;
  nlohmann::json s;
  s["study"] = study.name;
  s["file"] = study.file;
  s["beamrail_version"] = kVersion;
  s["type"] = "sweep";
  s["status"] = !written      ? status_name(Status::kFailed)
                : interrupted ? status_name(Status::kInterrupted)
                              : status_name(Status::kOk);
  s["message"] = !written      ? table.error()
                 : interrupted ? "interrupted by " + signal_name(signal) + " after " +
                                     std::to_string(finished) + " of " +
                                     std::to_string(run.designs) + " designs"
                               : "";
  s["warnings"] = study.input_warnings;
  s["designs"] = run.designs;
  s["designs_in_table"] = finished;
  s["evaluated_now"] = run.evaluated;
  s["resumed_from_table"] = table.resumed().size();
  s["failed_or_invalid"] = failed;
  s["designs_with_warnings"] = with_warnings;
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
  std::string summary_error;
  const bool summarized =
      write_file_atomically(settings.output / "summary.json", s.dump(2) + "\n", &summary_error);
  if (!written) {
    std::cerr << "beamrail: " << table.error() << "\n";
    if (!summarized) std::cerr << "beamrail: " << summary_error << "\n";
    return 1;
  }
  if (!summarized) {
    std::cerr << "beamrail: " << summary_error << "\n";
    return 1;
  }
  if (interrupted) {
    std::cerr << "beamrail: " << study.name << " interrupted by " << signal_name(signal) << ": "
              << finished << " of " << run.designs << " designs are in " << table.path().string()
              << "; continue with: " << settings.command << " --resume\n";
    return interrupted_exit_status(signal);
  }
  std::cout << study.name << ": " << run.designs << " designs (" << failed << " failed or invalid, "
            << with_warnings << " with warnings) in " << wall << " s -> "
            << settings.output.string() << "\n";
  return 0;
}

}  // namespace beamrail
