// VTK files for ParaView (docs/study_files.md "VTK files"): `beamrail run STUDY --vtk` or
// "outputs": {"vtk": true} writes a vtk/ folder into the results with one .pvd collection per
// analysis, <analysis>.pvd, whose frames are three XML PolyData files (.vtp) each, the parts of
// the collection:
//
//   part 0 "bodies"    every drawn body (the free bodies and the fixed scene bodies, not ground)
//                      as a vertex at its centre; point data: the body axes as vectors axis_x,
//                      axis_y, axis_z and the displacement; cell data: body_index, body (name),
//                      generated, fixed;
//   part 1 "glyphs"    per body a box of its extent (the uniform box of the body's mass and
//                      principal inertia, along its principal axes) and a line from the centre to
//                      each point where an element or force attaches to it (a mistyped attachment
//                      point sticks out); cell data: body_index, lever (1 for those lines);
//   part 2 "elements"  every beam and rail as a curve through its deformed shape: the
//                      Euler-Bernoulli cubic between the attachment points in the element frame
//                      carried by body 1, with the end deflection and the end rotations of the
//                      element law (a single massless beam bends on screen; segments of a split
//                      beam are curves of their own), a rail from point 1 to its carriage and
//                      straight on to the ends of its travel; cell data: element_index, element
//                      (name), rail (1 for a rail), the end forces and moments of
//                      element_forces.csv (force_end1, moment_end1, force_end2, moment_end2, in
//                      the element frame), axial_force (fx at end 2: tension > 0) and stress (the
//                      largest end stress of max_stress); the frames of a mode hold no forces.
//                      Then every joint as a line from its point on body 1 to its point on body 2
//                      (cell data joint = 1, its end forces in the joint frame, axial_force and
//                      stress NaN, gap |p2 - p1|; gap is NaN for beams and rails).
//
// Frames: transient, one per output row (the frame times are the t column of timeseries.csv);
// static, the undeformed (time 0) and the deformed state (time 1); modal and buckling, per mode a
// cycle of kFramesPerCycle frames at times (mode - 1) + k / kFramesPerCycle, with the mode's
// shape as point data `shape` (the table's shape, unscaled) and the frames moved by `amplitude`
// (field data) times sin(2 pi k / kFramesPerCycle) along it. `displacement` is always measured
// from the scene's initial configuration, as in the tables. vtk/contents.json lists what was
// written (analyses, files, frames, modes, their bytes and the seconds spent writing them, the
// design drawn).
//
// Written by hand, not with the VTK library. What the files hold is three small PolyData sets a
// frame, which VTK's documented XML format (raw binary appended data) takes in ~200 lines
// (optimizer/output/vtp_file.hpp, .cpp); the library's headers (Debian libvtk9-dev) would add
// 149 packages and 335 MB to every machine that builds beamrail, even one that already has VTK's
// runtime (GDAL, HDF5, NetCDF, FFmpeg, the Java bindings come with it), for the same bytes. The
// tests read every file back with VTK's own reader (python3-vtk9, installed by the test set-up
// only) and compare it with the tables.
#pragma once

#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/analysis/buckling_analysis.hpp"
#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/transient.hpp"
#include "core/model/data.hpp"
#include "core/model/model.hpp"
#include "optimizer/run/drawing_sink.hpp"

namespace beamrail {

// Frames of one mode's animation cycle.
inline constexpr int kFramesPerCycle = 16;
// The animation moves the largest point of a mode by this fraction of the scene's size.
inline constexpr double kModeAmplitude = 0.1;

class SceneDrawing;

// The VTK files of one evaluation, into `directory` (<results>/vtk). Each analysis replaces its
// own files (<analysis>.pvd and the folder <analysis>/) and leaves the others'. Not thread-safe:
// one per evaluation.
class VtkOutput : public DrawingSink {
 public:
  explicit VtkOutput(std::filesystem::path directory);
  ~VtkOutput() override;
  VtkOutput(const VtkOutput&) = delete;
  VtkOutput& operator=(const VtkOutput&) = delete;

  // The undeformed scene and the equilibrium in `deformed`.
  bool write_static(const std::string& analysis, const Model& model, const Data& deformed,
                    std::string* error) override;
  // The elastic modes of `result` about the state in `about`.
  bool write_modes(const std::string& analysis, const Model& model, const Data& about,
                   const ModalResult& result, std::string* error) override;
  // The buckling shapes of `result` about the reference state in `about`.
  bool write_buckling(const std::string& analysis, const Model& model, const Data& about,
                      const BucklingResult& result, std::string* error) override;

  // A transient: begin_series, then frame() per output row (it throws std::runtime_error naming
  // the file and the reason when a frame cannot be written), then end_series(), also after a
  // failed run (the collection holds the frames written).
  bool begin_series(const std::string& analysis, const Model& model, std::string* error) override;
  void frame(double t, const Data& data) override;
  bool end_series(std::string* error) override;

  // Writes contents.json: what each analysis wrote, and `design` (the design drawn, for a design
  // study; null for a single run).
  bool finish(const nlohmann::json& design, std::string* error);

  const std::filesystem::path& directory() const { return directory_; }
  // Bytes written so far.
  long long bytes() const { return bytes_; }

 private:
  struct Series;
  bool start_analysis(const std::string& analysis, const std::string& type, std::string* error);
  bool write_shapes(const std::string& analysis, const std::string& type, const Model& model,
                    const Data& about, const std::vector<Eigen::VectorXd>& shapes,
                    const std::vector<std::pair<int, double>>& labels, std::string* error);
  bool write_shape_frames(const std::string& analysis, const std::string& type, const Model& model,
                          const Data& about, const std::vector<Eigen::VectorXd>& shapes,
                          const std::vector<std::pair<int, double>>& labels, std::string* error);
  bool write_static_frames(const std::string& analysis, const Model& model, const Data& deformed,
                           std::string* error);

  std::filesystem::path directory_;
  nlohmann::json contents_ = nlohmann::json::array();
  std::unique_ptr<Series> series_;
  long long bytes_ = 0;
};

}  // namespace beamrail
