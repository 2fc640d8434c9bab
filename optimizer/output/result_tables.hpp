// The result tables of a single run (docs/study_files.md "Outputs"): time series, static
// displacements, element forces, modes and mode shapes.
#pragma once

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "core/analysis/buckling_analysis.hpp"
#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/transient.hpp"
#include "optimizer/output/tables.hpp"

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

// The tables of one analysis go to `directory`, their file names preceded by `prefix` ("" for an
// analysis named after its type, else "<name>."). Each replaces the previous one whole (written
// beside it and renamed).

// static_displacements.csv (free bodies: dx, dy, dz and rotation vector rx, ry, rz) and
// element_forces.csv (end forces of every beam and rail, element axes).
bool write_static_tables(const std::filesystem::path& directory, const std::string& prefix,
                         const Model& model, const Data& data, std::string* error);

// modes.csv (mode, frequency_hz, kind; rigid-body modes first with mode 0; the dominant direction,
// then per direction x .. rz the participation, effective mass and its fraction of the total, see
// Mode::participation) and mode_shapes.csv (elastic modes, M-normalized, per free body).
bool write_modal_tables(const std::filesystem::path& directory, const std::string& prefix,
                        const Model& model, const ModalResult& result, std::string* error);

// buckling.csv (mode, factor, nonlinearity: BucklingMode::nonlinearity) and buckling_shapes.csv
// (mode, body, dx .. rz: the shape with its largest translation, or rotation times the
// characteristic length, 1).
bool write_buckling_tables(const std::filesystem::path& directory, const std::string& prefix,
                           const Model& model, const BucklingResult& result, std::string* error);

}  // namespace beamrail
