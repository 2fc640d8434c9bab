// Intermediate, validated descriptions of scene parts, read from JSON before the Model is built
// (segment masses must be known before centres of mass and attachment offsets are fixed).
#pragma once

#include <map>
#include <optional>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "core/model/model.hpp"
#include "core/scene/json_reader.hpp"

namespace beamrail {

// The numbers are of the model's scalar S (double, or HyperDual when the scene is built for the
// design sensitivities: the numbers at the seeded pointers carry their derivative).
template <class S>
struct MaterialSpecT {
  S e = 0.0, g = 0.0;  // [Pa]
  S density = 0.0;     // [kg/m^3], 0 when not given
};

template <class S>
struct BodySpecT {
  std::string name;
  Where where;
  bool fixed = false;       // true also for a driven body
  bool driven = false;      // moved as `motion` prescribes
  PrescribedMotion motion;  // (core/model/motion.hpp)
  bool generated = false;   // interior node of a segmented beam
  std::optional<S> mass;
  std::optional<Mat3T<S>> inertia;  // body axes
  Vec3T<S> position = Vec3T<S>::Zero();
  Vec4T<S> orientation = Vec4T<S>(1, 0, 0, 0);
  Vec3T<S> velocity = Vec3T<S>::Zero(), angular_velocity = Vec3T<S>::Zero();
};

// A lumped mass added to a body by a segmented beam: mass at a global point, inertia about that
// point in global axes.
template <class S>
struct PointMassT {
  S mass = 0.0;
  Vec3T<S> point = Vec3T<S>::Zero();
  Mat3T<S> inertia = Mat3T<S>::Zero();
};

template <class S>
struct ElementSpecT {
  std::string name;
  Where where;
  bool rail = false;
  RailType rail_type = RailType::kPrismatic;
  int body1 = 0, body2 = 0;  // indices into the body list (0 = ground)
  Vec3T<S> p1, p2, p3;
  MaterialSpecT<S> material;
  SectionPropertiesT<S> section;
  std::string material_name, section_name;
  S damping = 0.0;
  Formulation formulation = Formulation::kEnergy;
  long segments = 0;           // at most kMaxSegments, all elements together
  bool auto_segments = false;  // "segments": "auto": the count is chosen when the scene is built
  std::optional<S> min_length;
  std::optional<std::vector<S>> travel;  // rails: [min, max] of the carriage's coordinate
};

template <class S>
struct JointSpecT {
  std::string name;
  Where where;
  JointType type = JointType::kSpherical;
  int body1 = 0, body2 = 0;
  Vec3T<S> point = Vec3T<S>::Zero();
  Vec3T<S> axis = Vec3T<S>::UnitX();  // unit; revolute joints only
  S relative_compliance = 1e-6;
};

template <class S>
struct SceneSpecsT {
  // The JSON pointers whose numbers are the design parameter's, with their derivative with respect
  // to it (HyperDual scenes only): those numbers are read with that derivative in their e2 part.
  std::map<std::string, double> seeds;
  mutable std::set<std::string> seeds_read;  // the seeds a reader has read
  Vec3T<S> gravity = Vec3T<S>::Zero();
  std::map<std::string, MaterialSpecT<S>> materials;
  std::map<std::string, SectionPropertiesT<S>> sections;
  // Declared but invalid (already reported): elements using them are not reported again. When a
  // whole list is unusable (not an object or array, or an entry without a usable name), a name
  // that is not found is not reported either: it may be the one that could not be read.
  std::set<std::string> invalid_materials, invalid_sections;
  bool materials_incomplete = false, sections_incomplete = false, bodies_incomplete = false;
  std::set<std::string> element_names;  // beams, rails and joints share one name space
  std::vector<BodySpecT<S>> bodies;     // [0] is ground
  std::map<std::string, int> body_index;
  std::vector<ElementSpecT<S>> elements;
  long n_segments = 0;  // of the elements read so far (kMaxSegments + 1 once over the limit)
  std::vector<JointSpecT<S>> joints;
  std::vector<LoadT<S>> loads;
  std::vector<Vec3T<S>> load_points;    // global application point of each load
  std::vector<Where> load_where;        // where each load is given
  std::vector<std::string> load_cases;  // the case names loads give, in order of first use
};
using MaterialSpec = MaterialSpecT<double>;
using BodySpec = BodySpecT<double>;
using PointMass = PointMassT<double>;
using ElementSpec = ElementSpecT<double>;
using JointSpec = JointSpecT<double>;
using SceneSpecs = SceneSpecsT<double>;

// The number read at `at`: with its derivative when `at` is one of specs.seeds (HyperDual).
template <class S>
S seeded(const SceneSpecsT<S>& specs, double value, const Where& at) {
  if constexpr (std::is_same_v<S, double>) {
    return value;
  } else {
    const auto it = specs.seeds.find(at.pointer);
    if (it == specs.seeds.end()) return S(value);
    specs.seeds_read.insert(it->first);
    return S(value, 0.0, it->second, 0.0);
  }
}
template <class S>
Vec3T<S> seeded(const SceneSpecsT<S>& specs, const Vec3& value, const Where& at) {
  Vec3T<S> out;
  for (int i = 0; i < 3; ++i) out(i) = seeded(specs, value(i), at / static_cast<size_t>(i));
  return out;
}
template <class S>
std::optional<S> seeded(const SceneSpecsT<S>& specs, const std::optional<double>& value,
                        const Where& at) {
  if (!value) return std::nullopt;
  return seeded(specs, *value, at);
}
template <class S>
std::optional<Vec3T<S>> seeded(const SceneSpecsT<S>& specs, const std::optional<Vec3>& value,
                               const Where& at) {
  if (!value) return std::nullopt;
  return seeded(specs, *value, at);
}

// The value of a number of either scalar.
inline double value_of(double x) { return x; }
template <class S>
double value_of(const S& x) {
  return x.value();
}
template <class Derived>
auto values_of(const Eigen::MatrixBase<Derived>& m) {
  using S = typename Derived::Scalar;
  Eigen::Matrix<double, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime> out(m.rows(),
                                                                                    m.cols());
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c) out(r, c) = value_of(S(m(r, c)));
  return out;
}

// More segments than this in one scene, all beams together, would only exhaust memory and time
// (every one adds a body and 13 states; 1e5 segments load in well under a second).
constexpr long kMaxSegments = 100000;

// Readers for each part of a scene; each reports its own problems. Instantiated for double and
// HyperDual.
template <class S>
void read_materials(ObjectReader& scene, SceneSpecsT<S>& specs);
template <class S>
void read_sections(ObjectReader& scene, SceneSpecsT<S>& specs);
template <class S>
void read_bodies(ObjectReader& scene, SceneSpecsT<S>& specs);
template <class S>
void read_elements(ObjectReader& scene, SceneSpecsT<S>& specs, bool rails);
template <class S>
void read_loads(ObjectReader& scene, SceneSpecsT<S>& specs);
template <class S>
void read_joints(ObjectReader& scene, SceneSpecsT<S>& specs);

// Warnings (never errors) for what looks mistyped: members whose length, section area or mass is
// two orders of magnitude or more from the median of the scene's members, and attachment or load
// points far from their body (beyond 3 radii of gyration and the median member length). `scene`
// locates the scene object (section pointers are built from it).
void check_plausibility(const SceneSpecs& specs, const Where& scene, Diagnostics& diag);

// The element frame (columns x, y, z in global axes) of points 1, 2, 3; nullopt when points 1
// and 2 coincide or point 3 lies on the axis (reported at `where`).
std::optional<Mat3> element_frame(const Vec3& p1, const Vec3& p2, const Vec3& p3,
                                  const Where& where, Diagnostics& diag);
// The same frame of points already checked, on any scalar.
template <class S>
Mat3T<S> frame_of(const Vec3T<S>& p1, const Vec3T<S>& p2, const Vec3T<S>& p3) {
  const Vec3T<S> x = (p2 - p1).normalized();
  const Vec3T<S> off = p3 - p1;
  const Vec3T<S> y = off - off.dot(x) * x;
  Mat3T<S> frame;
  frame.col(0) = x;
  frame.col(1) = y.normalized();
  frame.col(2) = x.cross(frame.col(1));
  return frame;
}

}  // namespace beamrail
