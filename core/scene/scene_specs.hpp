// Intermediate, validated descriptions of scene parts, read from JSON before the Model is built
// (segment masses must be known before centres of mass and attachment offsets are fixed).
#pragma once

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/model/model.hpp"
#include "core/scene/json_reader.hpp"

namespace beamrail {

struct MaterialSpec {
  double e = 0.0, g = 0.0;  // [Pa]
  double density = 0.0;     // [kg/m^3], 0 when not given
};

struct BodySpec {
  std::string name;
  Where where;
  bool fixed = false;
  bool generated = false;  // interior node of a segmented beam
  std::optional<double> mass;
  std::optional<Mat3> inertia;  // body axes
  Vec3 position = Vec3::Zero();
  Vec4 orientation = Vec4(1, 0, 0, 0);
  Vec3 velocity = Vec3::Zero(), angular_velocity = Vec3::Zero();
};

// A lumped mass added to a body by a segmented beam: mass at a global point, inertia about that
// point in global axes.
struct PointMass {
  double mass = 0.0;
  Vec3 point = Vec3::Zero();
  Mat3 inertia = Mat3::Zero();
};

struct ElementSpec {
  std::string name;
  Where where;
  bool rail = false;
  RailType rail_type = RailType::kPrismatic;
  int body1 = 0, body2 = 0;  // indices into the body list (0 = ground)
  Vec3 p1, p2, p3;
  MaterialSpec material;
  SectionProperties section;
  std::string material_name, section_name;
  double damping = 0.0;
  Formulation formulation = Formulation::kEnergy;
  long segments = 0;           // at most kMaxSegments, all elements together
  bool auto_segments = false;  // "segments": "auto": the count is chosen when the scene is built
  std::optional<double> min_length;
  std::optional<std::vector<double>> travel;  // rails: [min, max] of the carriage's coordinate
};

struct JointSpec {
  std::string name;
  Where where;
  JointType type = JointType::kSpherical;
  int body1 = 0, body2 = 0;
  Vec3 point = Vec3::Zero();
  Vec3 axis = Vec3::UnitX();  // unit; revolute joints only
  double relative_compliance = 1e-6;
};

struct SceneSpecs {
  Vec3 gravity = Vec3::Zero();
  std::map<std::string, MaterialSpec> materials;
  std::map<std::string, SectionProperties> sections;
  // Declared but invalid (already reported): elements using them are not reported again. When a
  // whole list is unusable (not an object or array, or an entry without a usable name), a name
  // that is not found is not reported either: it may be the one that could not be read.
  std::set<std::string> invalid_materials, invalid_sections;
  bool materials_incomplete = false, sections_incomplete = false, bodies_incomplete = false;
  std::set<std::string> element_names;  // beams, rails and joints share one name space
  std::vector<BodySpec> bodies;         // [0] is ground
  std::map<std::string, int> body_index;
  std::vector<ElementSpec> elements;
  long n_segments = 0;  // of the elements read so far (kMaxSegments + 1 once over the limit)
  std::vector<JointSpec> joints;
  std::vector<Load> loads;
  std::vector<Vec3> load_points;        // global application point of each load
  std::vector<Where> load_where;        // where each load is given
  std::vector<std::string> load_cases;  // the case names loads give, in order of first use
};

// More segments than this in one scene, all beams together, would only exhaust memory and time
// (every one adds a body and 13 states; 1e5 segments load in well under a second).
constexpr long kMaxSegments = 100000;

// Readers for each part of a scene; each reports its own problems.
void read_materials(ObjectReader& scene, SceneSpecs& specs);
void read_sections(ObjectReader& scene, SceneSpecs& specs);
void read_bodies(ObjectReader& scene, SceneSpecs& specs);
void read_elements(ObjectReader& scene, SceneSpecs& specs, bool rails);
void read_loads(ObjectReader& scene, SceneSpecs& specs);
void read_joints(ObjectReader& scene, SceneSpecs& specs);

// Warnings (never errors) for what looks mistyped: members whose length, section area or mass is
// two orders of magnitude or more from the median of the scene's members, and attachment or load
// points far from their body (beyond 3 radii of gyration and the median member length). `scene`
// locates the scene object (section pointers are built from it).
void check_plausibility(const SceneSpecs& specs, const Where& scene, Diagnostics& diag);

// The element frame (columns x, y, z in global axes) of points 1, 2, 3; nullopt when points 1
// and 2 coincide or point 3 lies on the axis (reported at `where`).
std::optional<Mat3> element_frame(const Vec3& p1, const Vec3& p2, const Vec3& p3,
                                  const Where& where, Diagnostics& diag);

}  // namespace beamrail
