#include "optimizer/output/vtk_output.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <list>
#include <stdexcept>

#include "core/model/element_forces.hpp"
#include "core/model/element_kinds.hpp"
#include "core/model/element_kinematics.hpp"
#include "core/model/generalized.hpp"
#include "core/model/joint_forces.hpp"
#include "optimizer/output/summary.hpp"
#include "optimizer/output/tables.hpp"
#include "optimizer/output/vtp_file.hpp"

namespace beamrail {

namespace fs = std::filesystem;

namespace {

using namespace vtp;  // NOLINT: the file writer of this file alone

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Points along a curve: a whole beam or rail, and one segment of a split beam (its neighbours
// carry the shape on).
constexpr int kCurvePoints = 17;
constexpr int kSegmentCurvePoints = 5;
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

// What a frame draws and how: the drawn bodies with their glyphs and levers, the elements with
// their curves; the topology and the constant cell data once, the points per state.
class SceneDrawing {
 public:
  explicit SceneDrawing(const Model& model) : model_(model) {
    // The scene's size: the bounding box of the drawn bodies and the attachment points.
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    const auto extend = [&](const Vec3& p) { lo = lo.cwiseMin(p), hi = hi.cwiseMax(p); };
    const Data initial(model);
    for (size_t i = 1; i < model.bodies.size(); ++i) extend(model.bodies[i].position);
    for_each_element(model, [&](auto kind, const auto& e, int) {
      using Kind = decltype(kind);
      const int i1 = Kind::body1(e), i2 = Kind::body2(e);
      extend(centre(model, initial, i1) + initial.pose[i1].A * Kind::point1(e));
      extend(centre(model, initial, i2) + initial.pose[i2].A * Kind::point2(e));
    });
    size_ = (hi - lo).allFinite() ? (hi - lo).norm() : 0.0;
    if (!(size_ > 0.0)) size_ = characteristic_length(model);

    std::vector<std::string> body_names, element_names;
    std::vector<int32_t> body_index, glyph_body, element_index;
    std::vector<uint8_t> generated, fixed, glyph_kind, element_kind, joint_kind;
    for (size_t i = 1; i < model.bodies.size(); ++i) {
      const Body& b = model.bodies[i];
      Drawn d;
      d.body = static_cast<int>(i);
      d.corners = box(b);
      if (!b.generated) {
        for_each_element(model, [&](auto kind, const auto& e, int) {
          using Kind = decltype(kind);
          if (Kind::body1(e) == d.body) d.levers.push_back(Kind::point1(e));
          if (Kind::body2(e) == d.body) d.levers.push_back(Kind::point2(e));
        });
        for (const Load& l : model.loads)
          if (l.kind == LoadKind::kForce && l.body == d.body) d.levers.push_back(l.offset);
      }
      const int64_t centre_point = static_cast<int64_t>(bodies_.size());
      centre_verts_.add({centre_point});
      body_index.push_back(d.body);
      body_names.push_back(b.name);
      generated.push_back(b.generated);
      fixed.push_back(b.fixed);
      // Glyph part: 8 corners, then the lever ends.
      const int64_t first = n_glyph_points_;
      static const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                      {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
      for (const auto& face : faces) {
        glyph_polys_.add({first + face[0], first + face[1], first + face[2], first + face[3]});
        glyph_poly_body_.push_back(d.body);
      }
      // Each lever: a line from the centre (a point of its own in this part) to the attachment.
      int64_t next = first + 8;
      for (size_t k = 0; k < d.levers.size(); ++k, next += 2) {
        glyph_lines_.add({next, next + 1});
        glyph_line_body_.push_back(d.body);
      }
      n_glyph_points_ = next;
      bodies_.push_back(std::move(d));
    }
    glyph_body = glyph_line_body_;
    glyph_body.insert(glyph_body.end(), glyph_poly_body_.begin(), glyph_poly_body_.end());
    glyph_kind.assign(glyph_line_body_.size(), 1);
    glyph_kind.insert(glyph_kind.end(), glyph_poly_body_.size(), 0);

    const auto curve = [&](bool rail, int index, const ElementEnds& e, int n) {
      Curve c;
      c.rail = rail;
      c.index = index;
      c.element = {rail ? kElementKindIndex<RailKind> : kElementKindIndex<BeamKind>, index};
      c.ends = &e;
      for (int k = 0; k < n; ++k) c.s.push_back(static_cast<double>(k) / (n - 1));
      element_index.push_back(index);
      element_kind.push_back(rail);
      joint_kind.push_back(0);
      curves_.push_back(c);
    };
    for (size_t i = 0; i < model.beams.size(); ++i) {
      curve(false, static_cast<int>(i), model.beams[i].ends,
            model.beams[i].segment > 0 ? kSegmentCurvePoints : kCurvePoints);
      curves_.back().measure = rotation_measure(model.beams[i]);
      element_names.push_back(model.beams[i].name);
    }
    for (size_t i = 0; i < model.rails.size(); ++i) {
      const Rail& r = model.rails[i];
      curve(true, static_cast<int>(i), r.ends, kCurvePoints);
      curves_.back().measure = rotation_measure(r);
      curves_.back().lower = r.travel_min, curves_.back().upper = r.travel_max;
      element_names.push_back(r.name);
    }
    // A joint: a line from its point on body 1 to its point on body 2 (as long as its gap).
    for (size_t i = 0; i < model.joints.size(); ++i) {
      Curve c;
      c.joint = true;
      c.index = static_cast<int>(i);
      c.element = {kElementKindIndex<JointKind>, c.index};
      c.s = {0.0, 1.0};
      element_index.push_back(c.index);
      element_kind.push_back(0);
      joint_kind.push_back(1);
      element_names.push_back(model.joints[i].name);
      curves_.push_back(c);
    }
    for (Curve& c : curves_) {
      c.first = n_curve_points_;
      std::vector<int64_t> points;
      for (int k = 0; k < c.points(); ++k) points.push_back(n_curve_points_ + k);
      n_curve_points_ += c.points();
      curve_lines_.add(points);
    }

    body_index_ = number_bytes(body_index);
    body_names_ = string_bytes(body_names);
    generated_ = number_bytes(generated);
    fixed_ = number_bytes(fixed);
    glyph_body_ = number_bytes(glyph_body);
    glyph_kind_ = number_bytes(glyph_kind);
    element_index_ = number_bytes(element_index);
    element_names_ = string_bytes(element_names);
    element_kind_ = number_bytes(element_kind);
    joint_kind_ = number_bytes(joint_kind);
    place(initial, initial_);
  }

  // Point positions of the three parts for the state in `data`.
  struct Geometry {
    std::vector<Vec3> centres, glyphs, curves;
    std::vector<Vec3> axes[3];  // per drawn body
  };

  void place(const Data& data, Geometry& g) const {
    g.centres.resize(bodies_.size());
    g.glyphs.resize(static_cast<size_t>(n_glyph_points_));
    g.curves.resize(static_cast<size_t>(n_curve_points_));
    for (auto& a : g.axes) a.resize(bodies_.size());
    size_t next = 0;
    for (size_t k = 0; k < bodies_.size(); ++k) {
      const Drawn& d = bodies_[k];
      const Vec3 c = centre(model_, data, d.body);
      const Mat3& a = data.pose[d.body].A;
      g.centres[k] = c;
      for (int j = 0; j < 3; ++j) g.axes[j][k] = a.col(j);
      for (const Vec3& corner : d.corners) g.glyphs[next++] = c + a * corner;
      for (const Vec3& r : d.levers) {
        g.glyphs[next++] = c;
        g.glyphs[next++] = c + a * r;
      }
    }
    for (const Curve& c : curves_) draw(c, data, g.curves.data() + c.first);
  }

  // The shape of a mode (generalized coordinates, free-body order) at every point: exact at the
  // bodies' points (they move rigidly), by central differences along the curves.
  void shape(const Data& about, const Eigen::VectorXd& x, Geometry& out) const {
    out.centres.assign(bodies_.size(), Vec3::Zero());
    out.glyphs.assign(static_cast<size_t>(n_glyph_points_), Vec3::Zero());
    size_t next = 0;
    for (size_t k = 0; k < bodies_.size(); ++k) {
      const Drawn& d = bodies_[k];
      const int f = model_.bodies[d.body].free_index;
      const Vec3 dc = f >= 0 ? Vec3(x.segment<3>(6 * f)) : Vec3::Zero();
      const Vec3 dt = f >= 0 ? Vec3(x.segment<3>(6 * f + 3)) : Vec3::Zero();
      const Mat3& a = about.pose[d.body].A;
      out.centres[k] = dc;
      for (const Vec3& corner : d.corners) out.glyphs[next++] = dc + dt.cross(a * corner);
      for (const Vec3& r : d.levers) {
        out.glyphs[next++] = dc;
        out.glyphs[next++] = dc + dt.cross(a * r);
      }
    }
    // The step moves the largest point by 1e-5 of the scene: the differences' error is ~1e-10.
    double largest = 0.0;
    for (int f = 0; f < model_.n_free(); ++f)
      largest = std::max(largest, x.segment<3>(6 * f).norm() + x.segment<3>(6 * f + 3).norm() *
                                                                   characteristic_length(model_));
    out.curves.assign(static_cast<size_t>(n_curve_points_), Vec3::Zero());
    if (!(largest > 0.0)) return;
    const double h = 1e-5 * size_ / largest;
    Data work(model_);
    Geometry plus, minus;
    moved(about, x * h, work);
    place(work, plus);
    moved(about, x * -h, work);
    place(work, minus);
    for (size_t i = 0; i < out.curves.size(); ++i)
      out.curves[i] = (plus.curves[i] - minus.curves[i]) / (2.0 * h);
  }

  // `work` set to `about` moved by dx.
  void moved(const Data& about, const Eigen::VectorXd& dx, Data& work) const {
    work.pose = about.pose;
    work.q = about.q;
    work.rotation = about.rotation;
    apply_increment(model_, work, dx);
  }

  // End forces of every element (beams, then rails, then joints) in the state of `data`; the
  // joints' gaps |p2 - p1| (NaN for beams and rails).
  void forces(const Data& data, std::vector<EndForces>& out, std::vector<double>& stress,
              std::vector<double>& gaps) const {
    out.resize(curves_.size());
    stress.resize(curves_.size());
    gaps.resize(curves_.size());
    for (size_t k = 0; k < curves_.size(); ++k)
      visit_element(model_, curves_[k].element, [&](auto kind, const auto& e, int index) {
        using Kind = decltype(kind);
        out[k] = Kind::end_forces(model_, data.pose, index);
        stress[k] = Kind::stress(e, out[k]);
        gaps[k] = Kind::gap(e, data.pose[Kind::body1(e)], data.pose[Kind::body2(e)]);
      });
  }

  const Geometry& initial() const { return initial_; }
  double size() const { return size_; }
  const Model& model() const { return model_; }

  // Constant parts of the files.
  Cells centre_verts_, glyph_lines_, glyph_polys_, curve_lines_;
  std::string body_index_, body_names_, generated_, fixed_, glyph_body_, glyph_kind_,
      element_index_, element_names_, element_kind_, joint_kind_;

 private:
  struct Drawn {
    int body = 0;
    std::array<Vec3, 8> corners;  // body axes, from the centre
    std::vector<Vec3> levers;     // attachment points, body axes, from the centre
  };
  struct Curve {
    ElementRef element;
    bool rail = false;
    bool joint = false;                                  // index is a joint's; ends is null
    RotationMeasure measure = RotationMeasure::kAngles;  // the element's (slopes from phi)
    int index = 0;
    const ElementEnds* ends = nullptr;
    std::vector<double> s;                                    // fractions of the deformable length
    double lower = -std::numeric_limits<double>::infinity();  // a rail's travel
    double upper = std::numeric_limits<double>::infinity();
    int64_t first = 0;
    int points() const {
      return static_cast<int>(s.size()) + std::isfinite(lower) + std::isfinite(upper);
    }
  };

  // The uniform box of the body's mass and principal inertia (each edge at least 1e-3 of the
  // scene), its corners in body axes; a fixed body without mass: a cube of 2 % of the scene.
  std::array<Vec3, 8> box(const Body& b) const {
    Vec3 half = Vec3::Constant(0.01 * size_);
    Mat3 axes = Mat3::Identity();
    if (b.mass > 0.0 && b.inertia.allFinite() && b.inertia.norm() > 0.0) {
      Eigen::SelfAdjointEigenSolver<Mat3> eig(b.inertia);
      axes = eig.eigenvectors();
      const Vec3 j = eig.eigenvalues();
      for (int i = 0; i < 3; ++i) {
        const double sq = 6.0 * (j((i + 1) % 3) + j((i + 2) % 3) - j(i)) / b.mass;
        half(i) = 0.5 * std::sqrt(std::max(sq, 0.0));
      }
      half = half.cwiseMax(Vec3::Constant(5e-4 * size_));
    }
    std::array<Vec3, 8> corners;
    for (int k = 0; k < 8; ++k)
      corners[k] = axes * Vec3((k & 1 ? 1 : -1) * half(0), (k & 2 ? 1 : -1) * half(1),
                               (k & 4 ? 1 : -1) * half(2));
    return corners;
  }

  // The curve's points: the Euler-Bernoulli cubic in the frame E1 carried by body 1, from point 1
  // to point 2 (a rail: to the carriage, then straight on along its end slope to the travel's end
  // beyond it, and straight along the rail's axis behind point 1).
  void draw(const Curve& c, const Data& data, Vec3* out) const {
    if (c.joint) {
      const Joint& j = model_.joints[c.index];
      out[0] = centre(model_, data, j.body1) + data.pose[j.body1].A * j.r1;
      out[1] = centre(model_, data, j.body2) + data.pose[j.body2].A * j.r2;
      return;
    }
    const ElementEnds& e = *c.ends;
    const Pose<double>& b1 = data.pose[e.body1];
    const ElementFrames<double> f = element_frames(e, b1, data.pose[e.body2], c.measure);
    const Vec3 p1 = centre(model_, data, e.body1) + f.R1;
    const double l = f.xi(0);
    const double slope_y = f.phi(2), slope_z = -f.phi(1);
    const auto local = [&](double x) -> Vec3 {
      // Beyond the carriage: straight on; behind point 1: the axis.
      const bool beyond = l >= 0.0 ? x > l : x < l;
      const bool behind = l >= 0.0 ? x < 0.0 : x > 0.0;
      if (behind) return Vec3(x, 0.0, 0.0);
      if (beyond) return Vec3(x, f.xi(1) + slope_y * (x - l), f.xi(2) + slope_z * (x - l));
      const double s = l != 0.0 ? x / l : 0.0;
      const double h = s * s * (3.0 - 2.0 * s), g = l * s * s * (s - 1.0);
      return Vec3(x, f.xi(1) * h + slope_y * g, f.xi(2) * h + slope_z * g);
    };
    int n = 0;
    if (std::isfinite(c.lower)) out[n++] = p1 + f.E1 * local(c.lower);
    const int m = static_cast<int>(c.s.size());
    for (int k = 0; k < m; ++k) {
      const double s = l >= 0.0 ? c.s[k] : c.s[m - 1 - k];  // ascending along the rail's axis
      if (s == 1.0) {
        out[n++] = p1 + f.E1 * f.xi;  // point 2 (the carriage)
        continue;
      }
      const double h = s * s * (3.0 - 2.0 * s), g = l * s * s * (s - 1.0);
      out[n++] = p1 + f.E1 * Vec3(s * l, f.xi(1) * h + slope_y * g, f.xi(2) * h + slope_z * g);
    }
    if (std::isfinite(c.upper)) out[n++] = p1 + f.E1 * local(c.upper);
  }

  const Model& model_;
  double size_ = 1.0;
  std::vector<Drawn> bodies_;
  std::vector<Curve> curves_;
  std::vector<int32_t> glyph_line_body_, glyph_poly_body_;
  int64_t n_glyph_points_ = 0, n_curve_points_ = 0;
  Geometry initial_;
};

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
