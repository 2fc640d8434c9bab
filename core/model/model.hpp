// Model: the immutable description of a scene, built once (by core/scene) and shared read-only by
// every analysis and every thread. Everything mutable lives in Data (core/model/data.hpp).
//
// Units are SI throughout. Body 0 is the implicit fixed `ground` at the origin.
#pragma once

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "core/model/motion.hpp"
#include "core/model/time_function.hpp"
#include "core/model/types.hpp"

namespace beamrail {

// The model's numbers are of a scalar type S: double for every analysis, a dual number for design
// sensitivities (core/analysis/sensitivity.hpp: the scene built on dual numbers carries the
// derivatives of every number with respect to a design parameter).
template <class S>
struct BodyT {
  std::string name;
  S mass = 0.0;                                 // kg (0 for fixed bodies that were given none)
  Mat3T<S> inertia = Mat3T<S>::Zero();          // about the centre of mass, body axes [kg m^2]
  Mat3T<S> inertia_inverse = Mat3T<S>::Zero();  // its inverse (free bodies only)
  Vec3T<S> position = Vec3T<S>::Zero();         // initial centre of mass, global [m]
  Vec4T<S> orientation = Vec4T<S>(1, 0, 0, 0);  // initial Euler parameters (body -> global)
  Vec3T<S> velocity = Vec3T<S>::Zero();  // initial velocity of the centre of mass, global [m/s]
  Vec3T<S> angular_velocity = Vec3T<S>::Zero();  // initial angular velocity, body axes [rad/s]
  bool fixed = false;   // true also for a driven body: no analysis solves for its motion
  bool driven = false;  // moved as `motion` prescribes (core/model/motion.hpp); fixed too
  PrescribedMotion motion;
  bool generated = false;  // interior body of a segmented beam
  S declared_mass = 0.0;   // the mass given in the scene, before segment masses
  int free_index = -1;     // position among the free bodies, -1 if fixed
};
using Body = BodyT<double>;

// Where an element attaches to its two bodies; computed once at set-up (docs/model.md).
template <class S>
struct ElementEndsT {
  int body1 = 0, body2 = 0;                // body indices
  Vec3T<S> r1 = Vec3T<S>::Zero();          // point 1 in body-1 axes, from its centre of mass [m]
  Vec3T<S> r2 = Vec3T<S>::Zero();          // point 2 in body-2 axes [m]
  Mat3T<S> frame1 = Mat3T<S>::Identity();  // element frame in body-1 axes (A_bl_1)
  Mat3T<S> frame2 = Mat3T<S>::Identity();  // element frame in body-2 axes (A_bl_2)
  Vec3T<S> centre_offset =
      Vec3T<S>::Zero();  // c2 - c1 of the bodies' reference centres, global [m]
  S length = 0.0;        // |p2 - p1| in the initial configuration [m]
};
using ElementEnds = ElementEndsT<double>;

// Which of the two force laws of docs/model.md an element uses.
enum class Formulation { kEnergy, kPaper };

// Cross-section properties kept for stress recovery and mass.
template <class S>
struct SectionPropertiesT {
  S area = 0.0;              // S [m^2]
  S torsion_constant = 0.0;  // Ix [m^4]
  S iy = 0.0, iz = 0.0;      // second moments about local y and z [m^4]
  S wy = 0.0, wz = 0.0;      // section moduli about y and z [m^3]; 0 when unknown
};
using SectionProperties = SectionPropertiesT<double>;

template <class S>
struct BeamT {
  std::string name;
  ElementEndsT<S> ends;
  S ea = 0.0;              // E S [N]
  S gj = 0.0;              // G Ix [N m^2]
  S eiy = 0.0, eiz = 0.0;  // E Iy, E Iz [N m^2]
  S damping = 0.0;         // stiffness-proportional beta [s]
  Formulation formulation = Formulation::kEnergy;
  SectionPropertiesT<S> section;
  S density = 0.0;    // kg/m^3, 0 when not given
  std::string group;  // the scene beam this element models (its own name if unsplit)
  int segment = 0;    // 1..n for the segments of a split beam, 0 otherwise
};
using Beam = BeamT<double>;

enum class RailType { kPrismatic, kCylindrical };

// A rail fixed to body 1 along its local x, on which body 2 (the carriage) slides.
template <class S>
struct RailT {
  std::string name;
  RailType type = RailType::kPrismatic;
  ElementEndsT<S> ends;    // ends.length: the initial carriage distance
  S gj = 0.0;              // G Ix; 0 for cylindrical rails [N m^2]
  S eiy = 0.0, eiz = 0.0;  // [N m^2]
  S min_length = 0.0;      // floor of |l| [m]
  // The carriage's axial coordinate l (from point 1 along the rail's x) must stay within
  // [travel_min, travel_max]: the rail's extent [m]; unbounded when not given.
  S travel_min = -std::numeric_limits<double>::infinity();
  S travel_max = std::numeric_limits<double>::infinity();
  S damping = 0.0;  // [s]
  Formulation formulation = Formulation::kEnergy;
  SectionPropertiesT<S> section;
  S density = 0.0;
};
using Rail = RailT<double>;

enum class JointType { kSpherical, kRevolute, kFixed };

// A joint between two bodies, modelled as a stiff penalty element (core/model/joint.hpp,
// docs/model.md "Joints"): spherical keeps the two bodies' joint points together, revolute also
// keeps their axes aligned, fixed also keeps their frames aligned.
template <class S>
struct JointT {
  std::string name;
  JointType type = JointType::kSpherical;
  int body1 = 0, body2 = 0;
  // The joint point in body axes, from the centres [m].
  Vec3T<S> r1 = Vec3T<S>::Zero(), r2 = Vec3T<S>::Zero();
  // The joint frame in each body's axes (equal in global axes initially); column 0 is the axis.
  Mat3T<S> frame1 = Mat3T<S>::Identity(), frame2 = Mat3T<S>::Identity();
  // The joint point from each centre in the initial configuration, global: A0 r (the gap is the
  // two points' displacements apart, so that coordinates far from the centres round nothing).
  Vec3T<S> lever1 = Vec3T<S>::Zero(), lever2 = Vec3T<S>::Zero();
  S relative_compliance = 1e-6;  // the penalty stiffness is the scene's scale over this
  S k_force = 0.0;               // [N/m]
  S k_moment = 0.0;              // [N m/rad]
};
using Joint = JointT<double>;

enum class LoadKind { kForce, kTorque };

template <class S>
struct LoadT {
  LoadKind kind = LoadKind::kForce;
  int body = 0;
  Vec3T<S> offset =
      Vec3T<S>::Zero();  // force: point of application in body axes, from the centre [m]
  // [N] or [N m], scaled by time(t): in global axes, or in body axes when `follows`
  Vec3T<S> value = Vec3T<S>::Zero();
  // A follower load: its value is fixed in the body frame and turns with the body (global value
  // A value); otherwise its direction stays fixed in global axes.
  bool follows = false;
  TimeFunctionT<S> time;
  std::string load_case;  // the load case it belongs to; empty: none (applied by every analysis)
};
using Load = LoadT<double>;

// One element of a model: the position of its kind in ElementKinds (core/model/element_kinds.hpp)
// and its index in that kind's array.
struct ElementRef {
  int kind = 0;
  int index = 0;
};

// Couplings between free bodies: the non-zero 6 x 6 blocks of tangent matrices, computed once.
struct BlockPattern {
  struct Block {
    int row = 0, col = 0;  // free-body indices
  };
  std::vector<Block> blocks;  // diagonal blocks first (block k = free body k)
  // Per element, in the order of for_each_element (core/model/element_kinds.hpp: the beams, the
  // rails, the joints), the block index of (end a, end b) for a, b in {1, 2}, or -1 when either
  // end is a fixed body: [0] = (1,1), [1] = (1,2), [2] = (2,1), [3] = (2,2).
  std::vector<std::array<int, 4>> element_blocks;
  std::vector<int> transposed;  // per block, the index of the block (col, row)
};

// How many segments "segments": "auto" gave a beam, and why (core/scene/auto_segments.hpp).
struct SegmentChoice {
  std::string beam;               // the scene beam's name
  long segments = 0;              // the count used
  double first_frequency_hz = 0;  // the beam's first clamped-free bending frequency at that count
  double estimated_error = 0;     // the largest estimated relative error of the checked ones
  int frequencies_checked = 0;    // per bending plane, the most frequencies checked
  bool reached = true;            // false: the largest count missed the target
  bool pinned = false;            // true: the count of the study's scene, kept for this design
};

template <class S>
struct ModelT {
  std::vector<BodyT<S>> bodies;  // [0] is ground
  std::vector<BeamT<S>> beams;
  std::vector<RailT<S>> rails;
  std::vector<JointT<S>> joints;
  std::vector<LoadT<S>> loads;
  Vec3T<S> gravity = Vec3T<S>::Zero();         // [m/s^2]
  std::vector<std::string> load_cases;         // the names loads give as their case, in scene order
  std::vector<SegmentChoice> segment_choices;  // of the beams with "segments": "auto"

  std::vector<int> free_bodies;    // body index of each free body, in state order
  std::vector<int> driven_bodies;  // body index of each driven body
  int n_states = 0;                // 13 per free body: u(3), q(4), v(3), w(3)
  int n_dofs = 0;                  // 6 per free body: dc(3), dtheta(3)
  BlockPattern pattern;

  int n_free() const { return static_cast<int>(free_bodies.size()); }

  // Fills free_bodies, n_states, n_dofs and pattern from bodies, beams, rails and joints. Called
  // once by the scene loader after the element arrays are final.
  void finalize();
};
using Model = ModelT<double>;
// A model whose numbers carry derivatives (core/model/hyper_dual.hpp).
struct HyperDual;
using DualModel = ModelT<HyperDual>;

// The model with only the loads for which keep(load) is true, and with gravity or without. Bodies,
// elements and the pattern are those of `model` (an analysis of one load case sees the same
// structure).
template <class S, class Keep>
ModelT<S> with_loads(const ModelT<S>& model, Keep&& keep, bool gravity) {
  ModelT<S> out = model;
  out.loads.clear();
  for (const LoadT<S>& load : model.loads)
    if (keep(load)) out.loads.push_back(load);
  if (!gravity) out.gravity = Vec3T<S>::Zero();
  return out;
}

// The loads an analysis of `load_case` applies: the loads without a case and those of the case
// ("": the loads without a case only); gravity always.
template <class S>
bool applies_in_case(const LoadT<S>& load, const std::string& load_case) {
  return load.load_case.empty() || load.load_case == load_case;
}

// The largest element length [m] (1 without elements): the length that turns rotations into
// displacements and moments into forces where the analyses compare them.
double characteristic_length(const Model& model);

// True when every free body is joined through beams and fixed joints (which resist all six
// relative motions) to a fixed body: the elastic stiffness is then positive definite (no rigid-body
// or mechanism mode). Spherical and revolute joints leave rotations free and do not count: a body
// they hang from is a pendulum, whose stiffness under no load is singular (docs/model.md "Joints").
bool held_by_beams(const Model& model);
// The free bodies (indices into Model::free_bodies) that are not so held: a mechanism's bodies and
// the bodies of floating parts.
std::vector<int> free_bodies_not_held(const Model& model);

constexpr int kStatesPerBody = 13;
constexpr int kDofsPerBody = 6;

}  // namespace beamrail
