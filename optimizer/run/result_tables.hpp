// The result tables of a single run's static, modal and buckling analyses as data
// (docs/study_files.md "Outputs"): static displacements, element forces, modes and mode shapes,
// buckling factors and shapes. output/result_tables.hpp files them.
#pragma once

#include <string>
#include <vector>

#include "core/analysis/buckling_analysis.hpp"
#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/static_analysis.hpp"
#include "core/model/data.hpp"

namespace beamrail {

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

// static_displacements.csv (free bodies: dx, dy, dz and rotation vector rx, ry, rz),
// element_forces.csv (end forces of every beam, rail and joint, element axes: a joint's frame) and,
// when the scene has joints, joint_gaps.csv (per joint: |p2 - p1|, p2 - p1 global, the angle of
// core/model/joint_forces.hpp joint_angle).
std::vector<ResultTable> static_tables(const std::string& prefix, const Model& model,
                                       const Data& data);

// static_path.csv of an arc-length path (StaticResult::path): per converged point and body of
// the path (the scene's own free bodies), the load factor, arc length from the start [m],
// corrector iterations and the body's displacement (dx, dy, dz, rotation vector rx, ry, rz).
ResultTable static_path_table(const std::string& prefix, const Model& model,
                              const StaticResult& result);

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

}  // namespace beamrail
