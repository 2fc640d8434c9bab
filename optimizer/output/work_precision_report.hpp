// The files of a work-precision study (docs/study_files.md "Outputs"): work_precision.csv, a row
// per run in plan order (written as runs end), and summary.json with the reference and the
// fastest run within the target error. Writing only: no run is made here, and nothing is printed
// (cli/batch_commands.hpp prints).
#pragma once

#include <map>
#include <string>

#include "optimizer/batch/run_settings.hpp"
#include "optimizer/batch/work_precision.hpp"
#include "optimizer/output/run_outcome.hpp"
#include "optimizer/output/tables.hpp"

namespace beamrail {

class WorkPrecisionTable {
 public:
  // Opens work_precision.csv (staged: the table of an earlier run stays until commit). False with
  // *error when it cannot be written.
  bool open(const std::filesystem::path& output, std::string* error);
  // Takes a run (in any order) and writes the runs that are next in plan order; false after a
  // write error.
  bool add(const PrecisionRun& run);
  // Writes the runs still held (after a gap: an interrupted run), and renames the table into
  // place; false with *error on any error so far.
  bool commit(std::string* error);

 private:
  void write(const PrecisionRun& run);
  CsvWriter table_;
  std::map<long, PrecisionRun> waiting_;
  long next_ = 0;
};

// What report_work_precision and report_no_runs wrote: the outcome (kOk; kFailed: the reference
// failed; kInterrupted; kWriteError) and what the messages say of the runs.
struct WorkPrecisionReport {
  RunOutcome outcome;
  bool in_reference = false;   // kInterrupted in the reference run, before any run
  long runs = 0, planned = 0;  // measured, of the plan
  long failed = 0;             // of them, failed or timed out
  // The fastest run within the target error (no method when none is).
  std::string fastest_method;
  double fastest_rtol = 0.0, fastest_seconds = 0.0;
};

// Writes summary.json (with the table's fate: `table_error` "" when it was written).
WorkPrecisionReport report_work_precision(const Study& study, const RunSettings& settings,
                                          const PrecisionReference& reference,
                                          const WorkPrecisionResult& result,
                                          const std::string& table_error);

// Writes summary.json for a study that ended before its runs (the reference failed or was
// interrupted, or the table cannot be written: `table_error`).
WorkPrecisionReport report_no_runs(const Study& study, const RunSettings& settings,
                                   const PrecisionReference& reference,
                                   const std::string& table_error);

}  // namespace beamrail
