// What a VTK frame draws (optimizer/output/vtk_output.cpp): every drawn body as a box of its
// inertia with levers to its attachment points, every element as a curve (the Euler-Bernoulli
// cubic of a beam or rail, a joint's line), and where their points are for a state or a mode.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/model/data.hpp"
#include "core/model/element_forces.hpp"
#include "core/model/element_kinds.hpp"
#include "core/model/element_kinematics.hpp"
#include "optimizer/output/vtp_file.hpp"

namespace beamrail {

// What a frame draws and how: the drawn bodies with their glyphs and levers, the elements with
// their curves; the topology and the constant cell data once, the points per state.
class SceneDrawing {
 public:
  explicit SceneDrawing(const Model& model);

  // Point positions of the three parts for the state in `data`.
  struct Geometry {
    std::vector<Vec3> centres, glyphs, curves;
    std::vector<Vec3> axes[3];  // per drawn body
  };

  void place(const Data& data, Geometry& g) const;

  // The shape of a mode (generalized coordinates, free-body order) at every point: exact at the
  // bodies' points (they move rigidly), by central differences along the curves.
  void shape(const Data& about, const Eigen::VectorXd& x, Geometry& out) const;

  // `work` set to `about` moved by dx.
  void moved(const Data& about, const Eigen::VectorXd& dx, Data& work) const;

  // End forces of every element (beams, then rails, then joints) in the state of `data`; the
  // joints' gaps |p2 - p1| (NaN for beams and rails).
  void forces(const Data& data, std::vector<EndForces>& out, std::vector<double>& stress,
              std::vector<double>& gaps) const;

  const Geometry& initial() const { return initial_; }
  double size() const { return size_; }
  const Model& model() const { return model_; }

  // Constant parts of the files.
  vtp::Cells centre_verts_, glyph_lines_, glyph_polys_, curve_lines_;
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
  std::array<Vec3, 8> box(const Body& b) const;

  // The curve's points: the Euler-Bernoulli cubic in the frame E1 carried by body 1, from point 1
  // to point 2 (a rail: to the carriage, then straight on along its end slope to the travel's end
  // beyond it, and straight along the rail's axis behind point 1).
  void draw(const Curve& c, const Data& data, Vec3* out) const;

  const Model& model_;
  double size_ = 1.0;
  std::vector<Drawn> bodies_;
  std::vector<Curve> curves_;
  std::vector<int32_t> glyph_line_body_, glyph_poly_body_;
  int64_t n_glyph_points_ = 0, n_curve_points_ = 0;
  Geometry initial_;
};

}  // namespace beamrail
