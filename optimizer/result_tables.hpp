// The result tables of a single run (SPEC.md "Outputs"): time series, static displacements,
// element forces, modes and mode shapes.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/transient.hpp"
#include "optimizer/tables.hpp"

namespace beamrail {

// timeseries.csv: t, then <body>.x,.y,.z,.q0..q3 for each free scene body, then energy.
class TimeseriesWriter {
 public:
  bool open(const std::filesystem::path& path, const Model& model, std::string* error);
  void write(const TransientSample& sample, const Data& data);
  void flush() { table_.flush(); }
  bool good() const { return table_.good(); }

 private:
  std::vector<int> bodies_;
  std::vector<Vec3> reference_;  // per listed body: its reference position
  std::vector<double> row_;
  CsvWriter table_;
};

// static_displacements.csv (free bodies: dx, dy, dz and rotation vector rx, ry, rz) and
// element_forces.csv (end forces of every beam and rail, element axes).
bool write_static_tables(const std::filesystem::path& directory, const Model& model,
                         const Data& data, std::string* error);

// modes.csv (mode, frequency_hz, kind; rigid-body modes first with mode 0) and mode_shapes.csv
// (elastic modes, M-normalized, per free body).
bool write_modal_tables(const std::filesystem::path& directory, const Model& model,
                        const ModalResult& result, std::string* error);

}  // namespace beamrail
