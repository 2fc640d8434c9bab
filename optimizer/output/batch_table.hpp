// The table of a batch run (samples.csv, history.csv): rows are appended by any thread as designs
// finish, each row in one write call, so an interrupted run leaves only whole rows; a resumed run
// reads them back; at the end the table is rewritten in canonical order, atomically, so that the
// result does not depend on the number of threads or on interruptions.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

namespace beamrail {

using CsvRow = std::vector<std::string>;

// Splits one CSV line (quoted fields may hold commas and doubled quotes).
CsvRow parse_csv_line(const std::string& line);

class BatchTable {
 public:
  enum class Opened { kOk, kOtherColumns, kWriteError };

  // Starts the table at path. Fresh: truncates and writes the header. Resume: requires the same
  // header (kOtherColumns otherwise), returns the whole rows already there in `existing`, and
  // drops an unfinished last line. *error names the file and the reason.
  Opened open(const std::filesystem::path& path, const CsvRow& header, bool resume,
              std::vector<CsvRow>* existing, std::string* error);

  // Appends one row (thread-safe); false after a write error (the table then takes no more rows,
  // and the part of the row that reached the file is cut off again).
  bool append(const CsvRow& row);

  // The first write error ("cannot write <path>: <reason>"), empty when none (thread-safe).
  std::string error();

  // Rewrites the table with its rows sorted by the numeric key columns, through a temporary
  // file and a rename. Rows with identical keys keep only the first.
  bool finalize(const std::vector<int>& key_columns, std::string* error);

 private:
  std::filesystem::path path_;
  CsvRow header_;
  int fd_ = -1;
  off_t written_ = 0;  // bytes of whole rows
  std::string error_;
  std::mutex mutex_;
};

}  // namespace beamrail
