#include "optimizer/output/scene_drawing.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "core/model/generalized.hpp"

namespace beamrail {

namespace {

using namespace vtp;  // NOLINT: the file writer's cell and byte helpers

// Points along a curve: a whole beam or rail, and one segment of a split beam (its neighbours
// carry the shape on).
constexpr int kCurvePoints = 17;
constexpr int kSegmentCurvePoints = 5;

}  // namespace

SceneDrawing::SceneDrawing(const Model& model) : model_(model) {
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

void SceneDrawing::place(const Data& data, Geometry& g) const {
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

void SceneDrawing::shape(const Data& about, const Eigen::VectorXd& x, Geometry& out) const {
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
    largest = std::max(largest, x.segment<3>(6 * f).norm() +
                                    x.segment<3>(6 * f + 3).norm() * characteristic_length(model_));
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

void SceneDrawing::moved(const Data& about, const Eigen::VectorXd& dx, Data& work) const {
  work.pose = about.pose;
  work.q = about.q;
  work.rotation = about.rotation;
  apply_increment(model_, work, dx);
}

void SceneDrawing::forces(const Data& data, std::vector<EndForces>& out,
                          std::vector<double>& stress, std::vector<double>& gaps) const {
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

std::array<Vec3, 8> SceneDrawing::box(const Body& b) const {
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

void SceneDrawing::draw(const Curve& c, const Data& data, Vec3* out) const {
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

}  // namespace beamrail
