// The files of a sweep (docs/study_files.md "Outputs"): samples.csv, a row per design written as
// designs end and read back by --resume, then sorted into index order; summary.json. Writing
// only: no design is evaluated here, and nothing is printed (cli/batch_commands.hpp prints).
#pragma once

#include <set>
#include <string>

#include "optimizer/batch/sweep.hpp"
#include "optimizer/output/batch_table.hpp"
#include "optimizer/output/run_outcome.hpp"

namespace beamrail {

class SweepTable {
 public:
  SweepTable(const Study& study, const RunSettings& settings);

  // Opens samples.csv fresh or, with --resume, reading back its rows; anything but kOk with
  // error() saying why.
  BatchTable::Opened open();
  // The designs already in the table (--resume), and how many of them failed or had warnings.
  const std::set<long>& resumed() const { return resumed_; }
  long resumed_failed() const { return resumed_failed_; }
  long resumed_warned() const { return resumed_warned_; }

  // Appends the row of design `index`; false after a write error.
  bool append(long index, const Design& x, const DesignOutcome& o);
  // Sorts the table into index order; false with error() on failure (the rows written stay).
  bool finalize();
  const std::string& error() const { return error_; }
  std::filesystem::path path() const;

 private:
  const Study& study_;
  const RunSettings& settings_;
  BatchTable table_;
  std::set<long> resumed_;
  long resumed_failed_ = 0, resumed_warned_ = 0;
  std::string error_;
};

// What report_sweep wrote: the outcome (kOk, kInterrupted, kWriteError) and the counts of the
// whole table, this run's designs and those resumed.
struct SweepReport {
  RunOutcome outcome;
  long finished = 0;       // designs in the table
  long failed = 0;         // of them, failed or invalid
  long with_warnings = 0;  // of them, with warnings
};

// Writes summary.json. `written`: whether the table was (table.error() says why not).
SweepReport report_sweep(const Study& study, const RunSettings& settings, const SweepTable& table,
                         const SweepRun& run, bool written);

}  // namespace beamrail
