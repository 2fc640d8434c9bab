#include "optimizer/output/vtk_output.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "core/model/element_forces.hpp"
#include "optimizer/output/scene_drawing.hpp"
#include "optimizer/output/summary.hpp"
#include "optimizer/output/tables.hpp"
#include "optimizer/output/vtp_file.hpp"

namespace beamrail {

namespace fs = std::filesystem;

namespace {

using namespace vtp;  // NOLINT: the file writer of this file alone

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// The parts of a frame, in the order of the .pvd's part numbers.
constexpr const char* kParts[] = {"bodies", "glyphs", "elements"};

// Adds the time from its construction to its end to *seconds.
class Timer {
 public:
  explicit Timer(double* seconds) : seconds_(seconds) {}
  ~Timer() {
    *seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  Timer(const Timer&) = delete;
  Timer& operator=(const Timer&) = delete;

 private:
  double* seconds_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace

namespace {

// What one frame holds besides the points: the shape of a mode, the element forces.
struct FrameData {
  const SceneDrawing::Geometry* shape = nullptr;
  const std::vector<EndForces>* forces = nullptr;
  const std::vector<double>* stress = nullptr;
  const std::vector<double>* gaps = nullptr;
  std::vector<std::pair<std::string, double>> fields;
};

std::string differences(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  std::string bytes;
  bytes.reserve(a.size() * 3 * sizeof(double));
  for (size_t i = 0; i < a.size(); ++i) put(bytes, Vec3(a[i] - b[i]));
  return bytes;
}

// Writes the three files of one frame into `folder` as <k>.<part>.vtp.
bool write_frame(const SceneDrawing& d, const SceneDrawing::Geometry& g, const FrameData& data,
                 const fs::path& folder, long k, long long* written, std::string* error) {
  char stem[32];
  std::snprintf(stem, sizeof stem, "%06ld", k);
  const SceneDrawing::Geometry& initial = d.initial();

  // bodies: centres, axes, displacement
  {
    Vtp v;
    for (const auto& [name, value] : data.fields) v.field(name, value);
    const std::string points = vec3_bytes(g.centres);
    const std::string displacement = differences(g.centres, initial.centres);
    const std::string ax = vec3_bytes(g.axes[0]), ay = vec3_bytes(g.axes[1]),
                      az = vec3_bytes(g.axes[2]);
    std::string shape;
    v.points(&points, static_cast<long>(g.centres.size()));
    v.point_data("displacement", &displacement);
    if (data.shape) {
      shape = vec3_bytes(data.shape->centres);
      v.point_data("shape", &shape);
    }
    v.point_data("axis_x", &ax);
    v.point_data("axis_y", &ay);
    v.point_data("axis_z", &az);
    v.cell_data("body_index", &d.body_index_, 1, "Int32");
    v.cell_data("body", &d.body_names_, 1, "String");
    v.cell_data("generated", &d.generated_, 1, "UInt8");
    v.cell_data("fixed", &d.fixed_, 1, "UInt8");
    v.verts(&d.centre_verts_);
    if (!v.write(folder / (std::string(stem) + ".bodies.vtp"), written, error)) return false;
  }
  // glyphs: boxes and levers
  {
    Vtp v;
    for (const auto& [name, value] : data.fields) v.field(name, value);
    const std::string points = vec3_bytes(g.glyphs);
    const std::string displacement = differences(g.glyphs, initial.glyphs);
    std::string shape;
    v.points(&points, static_cast<long>(g.glyphs.size()));
    v.point_data("displacement", &displacement);
    if (data.shape) {
      shape = vec3_bytes(data.shape->glyphs);
      v.point_data("shape", &shape);
    }
    v.cell_data("body_index", &d.glyph_body_, 1, "Int32");
    v.cell_data("lever", &d.glyph_kind_, 1, "UInt8");
    v.lines(&d.glyph_lines_);
    v.polys(&d.glyph_polys_);
    if (!v.write(folder / (std::string(stem) + ".glyphs.vtp"), written, error)) return false;
  }
  // elements: curves and forces
  {
    Vtp v;
    for (const auto& [name, value] : data.fields) v.field(name, value);
    const std::string points = vec3_bytes(g.curves);
    const std::string displacement = differences(g.curves, initial.curves);
    std::string shape;
    v.points(&points, static_cast<long>(g.curves.size()));
    v.point_data("displacement", &displacement);
    if (data.shape) {
      shape = vec3_bytes(data.shape->curves);
      v.point_data("shape", &shape);
    }
    v.cell_data("element_index", &d.element_index_, 1, "Int32");
    v.cell_data("element", &d.element_names_, 1, "String");
    v.cell_data("rail", &d.element_kind_, 1, "UInt8");
    v.cell_data("joint", &d.joint_kind_, 1, "UInt8");
    std::string f1, m1, f2, m2, axial, stress, gap;
    if (data.forces) {
      for (size_t k = 0; k < data.forces->size(); ++k) {
        const EndForces& e = (*data.forces)[k];
        for (int c = 0; c < 3; ++c) {
          put(f1, e.end1(c)), put(m1, e.end1(3 + c));
          put(f2, e.end2(c)), put(m2, e.end2(3 + c));
        }
        // A joint's gap in place of an axial force (its fx is along an axis, not a tension).
        const double joint_gap = (*data.gaps)[k];
        put(axial, std::isnan(joint_gap) ? e.end2(0) : kNaN);
        put(stress, (*data.stress)[k]);
        put(gap, joint_gap);
      }
      v.cell_data("force_end1", &f1, 3);
      v.cell_data("moment_end1", &m1, 3);
      v.cell_data("force_end2", &f2, 3);
      v.cell_data("moment_end2", &m2, 3);
      v.cell_data("axial_force", &axial);
      v.cell_data("stress", &stress);
      v.cell_data("gap", &gap);
    }
    v.lines(&d.curve_lines_);
    if (!v.write(folder / (std::string(stem) + ".elements.vtp"), written, error)) return false;
  }
  return true;
}

// The .pvd collection of frames (time, frame number).
std::string collection(const std::string& analysis,
                       const std::vector<std::pair<double, long>>& frames) {
  std::string xml =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" "
      "byte_order=\"LittleEndian\">\n<Collection>\n";
  for (const auto& [t, k] : frames) {
    char stem[32];
    std::snprintf(stem, sizeof stem, "%06ld", k);
    for (int p = 0; p < 3; ++p)
      xml += "<DataSet timestep=\"" + format_number(t) + "\" part=\"" + std::to_string(p) +
             "\" name=\"" + kParts[p] + "\" file=\"" + analysis + "/" + stem + "." + kParts[p] +
             ".vtp\"/>\n";
  }
  xml += "</Collection>\n</VTKFile>\n";
  return xml;
}

}  // namespace

struct VtkOutput::Series {
  std::string analysis;
  double seconds = 0.0;  // spent drawing and writing
  long long bytes0 = 0;  // bytes_ when it began
  std::unique_ptr<SceneDrawing> drawing;
  SceneDrawing::Geometry geometry;
  std::vector<EndForces> forces;
  std::vector<double> stress, gaps;
  std::vector<std::pair<double, long>> frames;
};

VtkOutput::VtkOutput(fs::path directory) : directory_(std::move(directory)) {}
VtkOutput::~VtkOutput() = default;

bool VtkOutput::start_analysis(const std::string& analysis, const std::string& type,
                               std::string* error) {
  std::error_code ec;
  fs::create_directories(directory_, ec);
  if (!ec) fs::remove(directory_ / (analysis + ".pvd"), ec);
  if (!ec) fs::remove_all(directory_ / analysis, ec);
  if (!ec) fs::create_directories(directory_ / analysis, ec);
  if (ec) {
    *error = "cannot write " + (directory_ / analysis).string() + ": " + ec.message();
    return false;
  }
  for (auto it = contents_.begin(); it != contents_.end();)
    it = (*it)["name"] == analysis ? contents_.erase(it) : it + 1;
  contents_.push_back({{"name", analysis},
                       {"type", type},
                       {"pvd", analysis + ".pvd"},
                       {"parts", {kParts[0], kParts[1], kParts[2]}}});
  return true;
}

bool VtkOutput::write_static(const std::string& analysis, const Model& model, const Data& deformed,
                             std::string* error) {
  if (!start_analysis(analysis, "static", error)) return false;
  double seconds = 0.0;
  const long long bytes0 = bytes_;
  const bool ok = [&] {
    const Timer timer(&seconds);
    return write_static_frames(analysis, model, deformed, error);
  }();
  contents_.back()["seconds"] = seconds;
  contents_.back()["bytes"] = bytes_ - bytes0;
  return ok;
}

bool VtkOutput::write_static_frames(const std::string& analysis, const Model& model,
                                    const Data& deformed, std::string* error) {
  const SceneDrawing d(model);
  const Data initial(model);
  std::vector<EndForces> forces;
  std::vector<double> stress, gaps;
  SceneDrawing::Geometry g;
  const fs::path folder = directory_ / analysis;
  for (int k = 0; k < 2; ++k) {
    const Data& state = k == 0 ? initial : deformed;
    d.place(state, g);
    d.forces(state, forces, stress, gaps);
    FrameData fd;
    fd.forces = &forces;
    fd.stress = &stress;
    fd.gaps = &gaps;
    fd.fields = {{"TimeValue", k}};
    if (!write_frame(d, g, fd, folder, k, &bytes_, error)) return false;
  }
  contents_.back()["frames"] = 2;
  contents_.back()["times"] = {0, 1};
  contents_.back()["scene_size"] = d.size();
  return write_file_atomically(directory_ / (analysis + ".pvd"),
                               collection(analysis, {{0.0, 0}, {1.0, 1}}), error);
}

bool VtkOutput::write_shapes(const std::string& analysis, const std::string& type,
                             const Model& model, const Data& about,
                             const std::vector<Eigen::VectorXd>& shapes,
                             const std::vector<std::pair<int, double>>& labels,
                             std::string* error) {
  if (!start_analysis(analysis, type, error)) return false;
  double seconds = 0.0;
  const long long bytes0 = bytes_;
  const bool ok = [&] {
    const Timer timer(&seconds);
    return write_shape_frames(analysis, type, model, about, shapes, labels, error);
  }();
  contents_.back()["seconds"] = seconds;
  contents_.back()["bytes"] = bytes_ - bytes0;
  return ok;
}

bool VtkOutput::write_shape_frames(const std::string& analysis, const std::string& type,
                                   const Model& model, const Data& about,
                                   const std::vector<Eigen::VectorXd>& shapes,
                                   const std::vector<std::pair<int, double>>& labels,
                                   std::string* error) {
  const SceneDrawing d(model);
  const fs::path folder = directory_ / analysis;
  const double l = characteristic_length(model);
  std::vector<std::pair<double, long>> frames;
  nlohmann::json modes = nlohmann::json::array();
  Data work(model);
  SceneDrawing::Geometry g, shape;
  const bool modal = type == "modal";
  for (size_t m = 0; m < shapes.size(); ++m) {
    const Eigen::VectorXd& x = shapes[m];
    double largest = 0.0;
    for (int f = 0; f < model.n_free(); ++f)
      largest = std::max(largest, x.segment<3>(6 * f).norm() + x.segment<3>(6 * f + 3).norm() * l);
    const double amplitude = largest > 0.0 ? kModeAmplitude * d.size() / largest : 0.0;
    d.shape(about, x, shape);
    const long first = static_cast<long>(frames.size());
    for (int k = 0; k < kFramesPerCycle; ++k) {
      const double phase = 2.0 * M_PI * k / kFramesPerCycle;
      d.moved(about, x * (amplitude * std::sin(phase)), work);
      d.place(work, g);
      FrameData fd;
      fd.shape = &shape;
      const double t =
          static_cast<double>(labels[m].first - 1) + static_cast<double>(k) / kFramesPerCycle;
      fd.fields = {{"TimeValue", t},
                   {"mode", labels[m].first},
                   {modal ? "frequency_hz" : "factor", labels[m].second},
                   {"amplitude", amplitude},
                   {"phase", phase}};
      const long index = static_cast<long>(frames.size());
      if (!write_frame(d, g, fd, folder, index, &bytes_, error)) return false;
      frames.emplace_back(t, index);
    }
    modes.push_back({{"mode", labels[m].first},
                     {modal ? "frequency_hz" : "factor", json_number(labels[m].second)},
                     {"amplitude", amplitude},
                     {"first_frame", first},
                     {"frames", kFramesPerCycle}});
  }
  contents_.back()["frames"] = frames.size();
  contents_.back()["modes"] = modes;
  contents_.back()["frames_per_cycle"] = kFramesPerCycle;
  contents_.back()["scene_size"] = d.size();
  return write_file_atomically(directory_ / (analysis + ".pvd"), collection(analysis, frames),
                               error);
}

bool VtkOutput::write_modes(const std::string& analysis, const Model& model, const Data& about,
                            const ModalResult& result, std::string* error) {
  std::vector<Eigen::VectorXd> shapes;
  std::vector<std::pair<int, double>> labels;
  int n = 0;
  for (const Mode& mode : result.modes) {
    if (mode.kind == Mode::Kind::kRigid) continue;
    shapes.push_back(mode.shape);
    labels.emplace_back(++n, mode.frequency_hz);
  }
  return write_shapes(analysis, "modal", model, about, shapes, labels, error);
}

bool VtkOutput::write_buckling(const std::string& analysis, const Model& model, const Data& about,
                               const BucklingResult& result, std::string* error) {
  std::vector<Eigen::VectorXd> shapes;
  std::vector<std::pair<int, double>> labels;
  for (size_t m = 0; m < result.modes.size(); ++m) {
    shapes.push_back(result.modes[m].shape);
    labels.emplace_back(static_cast<int>(m) + 1, result.modes[m].factor);
  }
  return write_shapes(analysis, "buckling", model, about, shapes, labels, error);
}

bool VtkOutput::begin_series(const std::string& analysis, const Model& model, std::string* error) {
  if (!start_analysis(analysis, "transient", error)) return false;
  series_ = std::make_unique<Series>();
  series_->analysis = analysis;
  series_->bytes0 = bytes_;
  const Timer timer(&series_->seconds);
  series_->drawing = std::make_unique<SceneDrawing>(model);
  return true;
}

void VtkOutput::frame(double t, const Data& data) {
  Series& s = *series_;
  const Timer timer(&s.seconds);
  const SceneDrawing& d = *s.drawing;
  d.place(data, s.geometry);
  d.forces(data, s.forces, s.stress, s.gaps);
  FrameData fd;
  fd.forces = &s.forces;
  fd.stress = &s.stress;
  fd.gaps = &s.gaps;
  fd.fields = {{"TimeValue", t}};
  const long k = static_cast<long>(s.frames.size());
  std::string error;
  if (!write_frame(d, s.geometry, fd, directory_ / s.analysis, k, &bytes_, &error))
    throw std::runtime_error(error);
  s.frames.emplace_back(t, k);
}

bool VtkOutput::end_series(std::string* error) {
  if (!series_) return true;
  const std::unique_ptr<Series> s = std::move(series_);
  bool ok = false;
  {
    const Timer timer(&s->seconds);
    ok = write_file_atomically(directory_ / (s->analysis + ".pvd"),
                               collection(s->analysis, s->frames), error);
  }
  contents_.back()["frames"] = s->frames.size();
  contents_.back()["scene_size"] = s->drawing->size();
  contents_.back()["seconds"] = s->seconds;
  contents_.back()["bytes"] = bytes_ - s->bytes0;
  return ok;
}

bool VtkOutput::finish(const nlohmann::json& design, std::string* error) {
  nlohmann::json c;
  c["analyses"] = contents_;
  c["design"] = design;
  c["frames_per_cycle"] = kFramesPerCycle;
  c["mode_amplitude"] = kModeAmplitude;
  std::error_code ec;
  fs::create_directories(directory_, ec);
  return write_file_atomically(directory_ / "contents.json", c.dump(2) + "\n", error);
}

}  // namespace beamrail
