// The result tables of a single run (docs/study_files.md "Outputs"): time series, static
// displacements, element forces, modes and mode shapes.
#pragma once

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/analysis/buckling_analysis.hpp"
#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/transient.hpp"
#include "optimizer/output/tables.hpp"
#include "optimizer/run/result_tables.hpp"
#include "optimizer/run/transient_sink.hpp"

namespace beamrail {

// timeseries.csv: t, then <body>.x,.y,.z,.q0..q3 for each free scene body, then energy. Written
// as timeseries.csv.partial while the run lasts, its rows handed to the system at least every
// second (a killed run leaves the rows up to then), and renamed to timeseries.csv by commit().
class TimeseriesWriter {
 public:
  bool open(const std::filesystem::path& path, const Model& model, std::string* error);
  // Adds a row; throws std::runtime_error naming the file and the reason when it cannot be
  // written (the transient run then ends as failed).
  void write(const TransientSample& sample, const Data& data);
  // Writes the rest and renames the table into place (also after a failed or interrupted run:
  // its rows are kept). False with *error on any write error.
  bool commit(std::string* error) { return table_.commit(error); }
  bool good() const { return table_.good(); }

 private:
  std::vector<int> bodies_;
  std::vector<Vec3> reference_;  // per listed body: its reference position
  std::vector<double> row_;
  CsvWriter table_;
  std::chrono::steady_clock::time_point flushed_;
};

// Rows are handed to the system at least this often while a time series is written.
inline constexpr std::chrono::seconds kTimeseriesFlushInterval{1};

// The time series of an evaluation's transient analyses, each written to `directory` as its
// samples arrive (TimeseriesWriter).
class TimeseriesFiles : public TransientSink {
 public:
  explicit TimeseriesFiles(std::filesystem::path directory) : directory_(std::move(directory)) {}
  bool begin(const std::string& file, const Model& model, std::string* error) override;
  void sample(const TransientSample& sample, const Data& data) override;
  bool end(std::string* error) override;

 private:
  std::filesystem::path directory_;
  std::optional<TimeseriesWriter> writer_;
};

// Writes the tables to `directory`, each replacing the previous one whole (written beside it and
// renamed). Stops at the first error, false with *error naming the file.
bool write_result_tables(const std::filesystem::path& directory,
                         const std::vector<ResultTable>& tables, std::string* error);

}  // namespace beamrail
