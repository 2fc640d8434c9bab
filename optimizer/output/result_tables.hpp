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

// A table of one analysis as data: its file name (with the analysis's prefix), header and rows
// of formatted fields. An evaluation keeps those of its static, modal and buckling analyses
// (EvaluationOptions::result_tables); write_result_tables() files them.
struct ResultTable {
  std::string file;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

// The tables of one analysis, their file names preceded by `prefix` ("" for an analysis named
// after its type, else "<name>.").

// static_displacements.csv (free bodies: dx, dy, dz and rotation vector rx, ry, rz) and
// element_forces.csv (end forces of every beam and rail, element axes).
std::vector<ResultTable> static_tables(const std::string& prefix, const Model& model,
                                       const Data& data);

// modes.csv (mode, frequency_hz, kind; rigid-body modes first with mode 0; the dominant direction,
// then per direction x .. rz the participation, effective mass and its fraction of the total, see
// Mode::participation) and mode_shapes.csv (elastic modes, M-normalized, per free body).
std::vector<ResultTable> modal_tables(const std::string& prefix, const Model& model,
                                      const ModalResult& result);

// buckling.csv (mode, factor, nonlinearity: BucklingMode::nonlinearity) and buckling_shapes.csv
// (mode, body, dx .. rz: the shape with its largest translation, or rotation times the
// characteristic length, 1).
std::vector<ResultTable> buckling_tables(const std::string& prefix, const Model& model,
                                         const BucklingResult& result);

// Writes the tables to `directory`, each replacing the previous one whole (written beside it and
// renamed). Stops at the first error, false with *error naming the file.
bool write_result_tables(const std::filesystem::path& directory,
                         const std::vector<ResultTable>& tables, std::string* error);

}  // namespace beamrail
