#include "core/scene/scene_loader.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <string>

#include "core/model/hyper_dual.hpp"
#include "core/model/joint.hpp"
#include "core/model/rotation.hpp"
#include "core/scene/auto_segments.hpp"
#include "core/scene/scene_specs.hpp"

namespace beamrail {
namespace {

// Every function below runs on the model's scalar S: double, or HyperDual for the scene built
// for the design sensitivities (whose values are those of the double scene, already validated).

// Inertia of a point mass with rotary inertia `inertia_local` (element axes, about the point).
template <class S>
PointMassT<S> lumped(const S& mass, const Vec3T<S>& point, const Mat3T<S>& frame,
                     const Vec3T<S>& inertia_local) {
  return {mass, point, Mat3T<S>(frame * inertia_local.asDiagonal() * frame.transpose())};
}

// Splits every segmented beam into `segments` sub-beams joined by generated interior bodies, and
// collects the half-segment masses that go to the end bodies. An element with a density that is
// not split carries its mass lumped (docs/model.md "Mass"): a beam as one segment (half its mass
// at each free end body), a rail wholly on body 1 (the rail's body; the carriage slides along it)
// as a slender rod between its points. The dynamics then see the mass the mass response counts.
template <class S>
void split_segmented_beams(SceneSpecsT<S>& specs, std::vector<std::vector<PointMassT<S>>>& extra,
                           std::vector<ElementSpecT<S>>& out) {
  // By index: segments add bodies, not elements, but `out` may be specs.elements' successor.
  for (const ElementSpecT<S>& e : specs.elements) {
    const long n = std::max(e.segments, 1L);
    const Vec3T<S> step = (e.p2 - e.p1) / static_cast<double>(n);
    const S ls = step.norm();
    const S rho = e.material.density;
    const SectionPropertiesT<S>& s = e.section;
    const S ms = rho * s.area * ls;
    const Mat3T<S> frame = frame_of(e.p1, e.p2, e.p3);  // the points were validated when read
    // Rotary inertia of a slice of length a about its centre (element axes).
    auto slice = [&](const S& a) {
      const S m = rho * s.area * a;
      return Vec3T<S>(rho * a * (s.iy + s.iz), rho * a * s.iy + m * a * a / 12.0,
                      rho * a * s.iz + m * a * a / 12.0);
    };
    if (e.segments <= 0) {
      out.push_back(e);
      if (!(ms > 0.0)) continue;
      if (e.rail) {
        if (!specs.bodies[e.body1].fixed)
          extra[e.body1].push_back(lumped(ms, Vec3T<S>(0.5 * (e.p1 + e.p2)), frame, slice(ls)));
        continue;
      }
    }
    // Half segment about the end node: its slice inertia plus m (a/2)^2 for the bending axes.
    Vec3T<S> half = slice(0.5 * ls);
    const S mh = 0.5 * ms;
    half(1) += mh * 0.0625 * ls * ls;
    half(2) += mh * 0.0625 * ls * ls;
    if (!specs.bodies[e.body1].fixed) extra[e.body1].push_back(lumped(mh, e.p1, frame, half));
    if (!specs.bodies[e.body2].fixed) extra[e.body2].push_back(lumped(mh, e.p2, frame, half));
    if (e.segments <= 0) continue;  // an unsplit beam: its halves are placed

    // Interior bodies share the element's orientation; their velocities blend the ends'.
    // Copies: adding the interior bodies below may reallocate specs.bodies.
    const BodySpecT<S> b1 = specs.bodies[e.body1];
    const BodySpecT<S> b2 = specs.bodies[e.body2];
    const Mat3T<S> a1 = rotation_matrix<S>(b1.orientation), a2 = rotation_matrix<S>(b2.orientation);
    const Vec3T<S> om1 = a1 * b1.angular_velocity, om2 = a2 * b2.angular_velocity;
    int previous = e.body1;
    for (long k = 1; k <= n; ++k) {
      int next = e.body2;
      if (k < n) {
        const double s_k = static_cast<double>(k) / static_cast<double>(n);
        BodySpecT<S> node;
        node.name = e.name + ".node" + std::to_string(k);
        node.where = e.where;
        node.generated = true;
        node.position = e.p1 + static_cast<double>(k) * step;
        node.orientation = quaternion_of<S>(frame);
        const Vec3T<S> v1 = b1.velocity + om1.cross(node.position - b1.position);
        const Vec3T<S> v2 = b2.velocity + om2.cross(node.position - b2.position);
        node.velocity = (1.0 - s_k) * v1 + s_k * v2;
        node.angular_velocity = frame.transpose() * ((1.0 - s_k) * om1 + s_k * om2);
        node.mass = ms;
        const Vec3T<S> j = slice(ls);
        node.inertia = Mat3T<S>(j.asDiagonal());
        next = static_cast<int>(specs.bodies.size());
        specs.bodies.push_back(node);
        extra.emplace_back();
      }
      ElementSpecT<S> sub = e;
      sub.name = e.name + ".seg" + std::to_string(k);
      sub.segments = -k;  // marks "segment k of e.name"
      sub.body1 = previous, sub.body2 = next;
      sub.p1 = e.p1 + static_cast<double>(k - 1) * step;
      sub.p2 = sub.p1 + step;
      sub.p3 = e.p3 + static_cast<double>(k - 1) * step;
      out.push_back(sub);
      previous = next;
    }
  }
}

// Combines a body's own mass with the lumped masses of segments into one rigid body; returns the
// combined centre of mass and sets mass and inertia (body axes).
template <class S>
Vec3T<S> combine_masses(const BodySpecT<S>& b, const std::vector<PointMassT<S>>& extra, S* mass,
                        Mat3T<S>* inertia) {
  const Mat3T<S> a = rotation_matrix<S>(b.orientation);
  std::vector<PointMassT<S>> parts = extra;
  if (b.mass)
    parts.push_back(
        {*b.mass, b.position, Mat3T<S>(a * b.inertia.value_or(Mat3T<S>::Zero()) * a.transpose())});
  S m = 0.0;
  Vec3T<S> first = Vec3T<S>::Zero();
  for (const PointMassT<S>& p : parts) m += p.mass, first += p.mass * p.point;
  const Vec3T<S> c = m > 0.0 ? Vec3T<S>(first / m) : b.position;
  Mat3T<S> j = Mat3T<S>::Zero();
  for (const PointMassT<S>& p : parts) {
    const Vec3T<S> d = p.point - c;
    j += p.inertia + p.mass * (d.squaredNorm() * Mat3T<S>::Identity() - d * d.transpose());
  }
  *mass = m;
  *inertia = a.transpose() * j * a;
  return c;
}

// The first quantity of a body that is not finite ("mass", ...).
std::string out_of_range(const Body& b) {
  if (!std::isfinite(b.mass)) return "mass";
  if (!b.position.allFinite()) return "centre of mass";
  if (!b.inertia.allFinite()) return "inertia";
  return "initial velocity";
}

// The first quantity of an element that is not finite, or "".
std::string out_of_range(const ElementSpec& e, const ElementEnds& ends) {
  const SectionProperties& s = e.section;
  const double modulus_e = e.material.e, modulus_g = e.material.g;
  if (!std::isfinite(ends.length) || !ends.r1.allFinite() || !ends.r2.allFinite() ||
      !ends.frame1.allFinite() || !ends.frame2.allFinite())
    return "the geometry (length or attachment points)";
  if (!std::isfinite(s.area) || !std::isfinite(s.torsion_constant) || !std::isfinite(s.iy) ||
      !std::isfinite(s.iz) || !std::isfinite(s.wy) || !std::isfinite(s.wz))
    return "the section";
  if (!std::isfinite(modulus_e * s.area)) return "the axial stiffness E S";
  if (!std::isfinite(modulus_g * s.torsion_constant)) return "the torsional stiffness G Ix";
  if (!std::isfinite(modulus_e * s.iy) || !std::isfinite(modulus_e * s.iz))
    return "the bending stiffness E I";
  return "";
}

template <class S>
ElementEndsT<S> make_ends(const ElementSpecT<S>& e, const std::vector<BodyT<S>>& bodies) {
  ElementEndsT<S> ends;
  ends.body1 = e.body1;
  ends.body2 = e.body2;
  const Mat3T<S> frame = frame_of(e.p1, e.p2, e.p3);  // the points were validated when read
  const BodyT<S>& b1 = bodies[e.body1];
  const BodyT<S>& b2 = bodies[e.body2];
  const Mat3T<S> a1 = rotation_matrix<S>(b1.orientation), a2 = rotation_matrix<S>(b2.orientation);
  ends.r1 = a1.transpose() * (e.p1 - b1.position);
  ends.r2 = a2.transpose() * (e.p2 - b2.position);
  ends.frame1 = a1.transpose() * frame;
  ends.frame2 = a2.transpose() * frame;
  ends.length = (e.p2 - e.p1).norm();
  ends.centre_offset = b2.position - b1.position;
  return ends;
}

// The scene's "segmentation" object: what "segments": "auto" aims at.
SegmentationTarget read_segmentation(const Json& value, const Where& where, Diagnostics& diag) {
  SegmentationTarget target;
  ObjectReader r(value, where, diag);
  if (!r.is_object()) return target;
  if (const auto e = r.positive("frequency_error", false)) {
    if (*e < 1.0)
      target.frequency_error = *e;
    else
      r.error("frequency_error", "must be < 1 (a relative error: 1e-3 is 0.1 %)");
  }
  target.max_frequency_hz = r.positive("max_frequency_hz", false).value_or(0.0);
  return target;
}

// Sets the segment count of every beam with "segments": "auto" (pinned: the counts of the study's
// scene, kept by the designs built from it) and records the choices.
// A HyperDual scene takes every count from `pinned` (an unpinned beam is an error there).
template <class S>
void choose_auto_segments(SceneSpecsT<S>& specs, const SegmentationTarget& target,
                          const std::vector<SegmentChoice>* pinned, Diagnostics& diag,
                          std::vector<SegmentChoice>& choices) {
  std::map<std::array<double, 6>, SegmentChoice> by_beam;  // identical members choose once
  for (ElementSpecT<S>& e : specs.elements) {
    if (!e.auto_segments) continue;
    SegmentChoice c;
    const auto kept = pinned
                          ? std::find_if(pinned->begin(), pinned->end(),
                                         [&](const SegmentChoice& p) { return p.beam == e.name; })
                          : std::vector<SegmentChoice>::const_iterator();
    if (pinned && kept != pinned->end()) {
      c = *kept;
      c.pinned = true;
    } else if constexpr (!std::is_same_v<S, double>) {
      diag.error(e.where.file, (e.where / "segments").pointer,
                 "no count of the study's scene for this beam's \"auto\" segments");
      return;
    } else {
      const double rho = e.material.density;
      UniformBeam b;
      b.length = (e.p2 - e.p1).norm();
      b.ei[0] = e.material.e * e.section.iy, b.ei[1] = e.material.e * e.section.iz;
      b.rho_i[0] = rho * e.section.iy, b.rho_i[1] = rho * e.section.iz;
      b.rho_area = rho * e.section.area;
      const std::array<double, 6> key{b.length,   b.ei[0],    b.ei[1],
                                      b.rho_i[0], b.rho_i[1], b.rho_area};
      auto it = by_beam.find(key);
      if (it == by_beam.end()) it = by_beam.emplace(key, choose_segments(e.name, b, target)).first;
      c = it->second;
      c.beam = e.name;
      if (!c.reached) {
        char text[240];
        std::snprintf(text, sizeof text,
                      "beam \"%s\": %ld segments (the most \"auto\" gives) reach an estimated "
                      "bending-frequency error of %.2g, above the target %.2g",
                      e.name.c_str(), c.segments, c.estimated_error, target.frequency_error);
        diag.warning(e.where.file, (e.where / "segments").pointer, text);
      }
    }
    if (specs.n_segments + c.segments > kMaxSegments) {
      diag.error(e.where.file, (e.where / "segments").pointer,
                 "\"auto\" gives " + std::to_string(c.segments) + " segments: more than " +
                     std::to_string(kMaxSegments) + " in the scene, all beams together");
      return;
    }
    specs.n_segments += c.segments;
    e.segments = c.segments;
    choices.push_back(c);
  }
}

// The joints of the scene, with their penalty stiffness (core/model/joint.hpp) from the model's
// elements and loads; reports a joint point far from both its bodies: beyond 3 radii of gyration
// and beyond every element attachment point of each body (a fixed body reaches everywhere).
template <class S>
void build_joints(const SceneSpecsT<S>& specs, const std::vector<ElementSpecT<S>>& elements,
                  ModelT<S>& model, Diagnostics& diag) {
  std::vector<double> reach(model.bodies.size(), 0.0);
  for (size_t i = 0; i < model.bodies.size(); ++i) {
    const BodyT<S>& b = model.bodies[i];
    if (b.fixed) {
      reach[i] = std::numeric_limits<double>::infinity();
    } else {
      const Eigen::SelfAdjointEigenSolver<Mat3> eig(values_of(b.inertia));
      reach[i] = 3.0 * std::sqrt(eig.eigenvalues().maxCoeff() / value_of(b.mass));
    }
  }
  const auto distance = [](const Vec3T<S>& a, const Vec3T<S>& b) {
    return (values_of(a) - values_of(b)).norm();
  };
  for (const ElementSpecT<S>& e : elements) {
    reach[e.body1] = std::max(reach[e.body1], distance(e.p1, model.bodies[e.body1].position));
    reach[e.body2] = std::max(reach[e.body2], distance(e.p2, model.bodies[e.body2].position));
  }
  for (const JointSpecT<S>& s : specs.joints) {
    const BodyT<S>& b1 = model.bodies[s.body1];
    const BodyT<S>& b2 = model.bodies[s.body2];
    const double d1 = distance(s.point, b1.position), d2 = distance(s.point, b2.position);
    if (!(d1 <= reach[s.body1]) && !(d2 <= reach[s.body2])) {
      char text[240];
      std::snprintf(text, sizeof text,
                    "joint \"%s\": the point is %.6g m from body \"%s\" and %.6g m from body "
                    "\"%s\", beyond both bodies' extent (%.6g m, %.6g m: 3 radii of gyration "
                    "or the farthest element end)",
                    s.name.c_str(), d1, b1.name.c_str(), d2, b2.name.c_str(), reach[s.body1],
                    reach[s.body2]);
      diag.error(s.where.file, (s.where / "point").pointer, text);
      continue;
    }
    JointT<S> j;
    j.name = s.name;
    j.type = s.type;
    j.body1 = s.body1, j.body2 = s.body2;
    const Mat3T<S> a1 = rotation_matrix<S>(b1.orientation);
    const Mat3T<S> a2 = rotation_matrix<S>(b2.orientation);
    j.r1 = a1.transpose() * (s.point - b1.position);
    j.r2 = a2.transpose() * (s.point - b2.position);
    // The joint frame in global axes: the axis and two directions perpendicular to it (on other
    // scalars, the double frame's second direction kept perpendicular as the axis turns).
    Mat3T<S> frame;
    frame.col(0) = s.axis;
    if constexpr (std::is_same_v<S, double>) {
      frame.col(1) = s.axis.unitOrthogonal();
    } else {
      const Vec3T<S> e = Vec3(values_of(s.axis).unitOrthogonal()).cast<S>();
      frame.col(1) = (e - e.dot(s.axis) * s.axis).normalized();
    }
    frame.col(2) = s.axis.cross(frame.col(1));
    j.frame1 = a1.transpose() * frame;
    j.frame2 = a2.transpose() * frame;
    j.lever1 = s.point - b1.position;
    j.lever2 = s.point - b2.position;
    j.relative_compliance = s.relative_compliance;
    model.joints.push_back(j);
  }
  const auto [kt, kr] = joint_stiffness_scale(model);
  for (JointT<S>& j : model.joints) {
    j.k_force = kt / j.relative_compliance;
    j.k_moment = kr / j.relative_compliance;
  }
}

// The scene on scalar S (load_scene, load_dual_scene); a HyperDual scene checks only what its
// reading checks (its values are those of the double scene, built and checked before).
template <class S>
std::optional<ModelT<S>> build_scene(const Json& scene, const Where& where, Diagnostics& diag,
                                     const std::vector<SegmentChoice>* pinned,
                                     const std::map<std::string, double>& seeds) {
  constexpr bool checked = std::is_same_v<S, double>;
  const size_t errors_before = diag.size();
  SceneSpecsT<S> specs;
  specs.seeds = seeds;
  SegmentationTarget target;
  bool target_given = false;
  {
    ObjectReader r(scene, where, diag);
    if (!r.is_object()) return std::nullopt;
    specs.gravity = seeded(specs, r.vec3("gravity", false).value_or(Vec3::Zero()), r.at("gravity"));
    if (const Json* seg = r.member("segmentation", false)) {
      target = read_segmentation(*seg, r.at("segmentation"), diag);
      target_given = true;
    }
    read_materials(r, specs);
    read_sections(r, specs);
    read_bodies(r, specs);
    read_elements(r, specs, false);
    read_elements(r, specs, true);
    read_loads(r, specs);
    read_joints(r, specs);
  }
  if (diag.size() > errors_before) return std::nullopt;
  for (const auto& [pointer, derivative] : specs.seeds)
    if (!specs.seeds_read.count(pointer))
      diag.error(where.file, pointer,
                 "not a number the scene's build differentiates (a segment count, the "
                 "segmentation target, or no number of the scene)");
  if (diag.size() > errors_before) return std::nullopt;
  std::vector<SegmentChoice> choices;
  choose_auto_segments(specs, target, pinned, diag, choices);
  if (diag.size() > errors_before) return std::nullopt;
  if constexpr (checked) {
    if (target_given && choices.empty())
      diag.warning(where.file, (where / "segmentation").pointer,
                   "no beam has \"segments\": \"auto\": the segmentation target does nothing");
    check_plausibility(specs, where, diag);
  }

  std::vector<std::vector<PointMassT<S>>> extra(specs.bodies.size());
  std::vector<ElementSpecT<S>> elements;
  split_segmented_beams(specs, extra, elements);

  ModelT<S> model;
  model.gravity = specs.gravity;
  // One report per scene entry: the interior bodies of a segmented beam share their beam's.
  std::set<std::string> reported;
  auto body_error = [&](const BodySpecT<S>& s, const std::string& what) {
    if (!reported.insert(s.where.pointer).second) return;
    const std::string who = s.generated
                                ? "beam \"" + s.name.substr(0, s.name.rfind(".node")) + "\": "
                                : "body \"" + s.name + "\": ";
    diag.error(s.where.file, s.where.pointer, who + what);
  };
  for (size_t i = 0; i < specs.bodies.size(); ++i) {
    const BodySpecT<S>& s = specs.bodies[i];
    BodyT<S> b;
    b.name = s.name;
    b.fixed = s.fixed;
    b.driven = s.driven;
    b.motion = s.motion;
    b.generated = s.generated;
    b.declared_mass = b.generated ? S(0.0) : s.mass.value_or(S(0.0));
    b.orientation = s.orientation;
    b.velocity = s.velocity;
    b.angular_velocity = s.angular_velocity;
    b.position = combine_masses(s, extra[i], &b.mass, &b.inertia);
    if constexpr (!checked) {
      if (!b.fixed) b.inertia_inverse = b.inertia.inverse();
    } else {
      // Values each finite can still combine into an overflow (a density of 1e308, a centre 1e308
      // away): reported here rather than met as NaN in an analysis.
      if (!std::isfinite(b.mass) || !b.inertia.allFinite() || !b.position.allFinite() ||
          !b.velocity.allFinite() || !b.angular_velocity.allFinite()) {
        body_error(s, "the " + out_of_range(b) + (s.generated ? " of its interior bodies" : "") +
                          " is out of the range of double precision (not finite)");
        continue;
      }
      if (!b.fixed) {
        const Eigen::SelfAdjointEigenSolver<Mat3> eig(b.inertia);
        if (!(b.mass > 0.0) || !(eig.eigenvalues().minCoeff() > 0.0)) {
          if (s.generated)
            body_error(s,
                       "the mass or inertia of its interior bodies is zero in double precision "
                       "(density or section too small)");
          else
            diag.error(s.where.file, s.where.pointer,
                       "free body \"" + s.name +
                           "\" has no mass: give \"mass\" and \"inertia\", attach a segmented "
                           "beam, or set \"fixed\": true");
          continue;
        }
        b.inertia_inverse = b.inertia.inverse();
        if (!b.inertia_inverse.allFinite()) {
          body_error(s, std::string("the inertia") +
                            (s.generated ? " of its interior bodies" : "") +
                            " cannot be inverted in double precision (values too large or too "
                            "small)");
          continue;
        }
      }
    }
    model.bodies.push_back(b);
  }
  if (diag.size() > errors_before) return std::nullopt;

  reported.clear();  // now one report per scene element, not per segment
  for (const ElementSpecT<S>& e : elements) {
    const ElementEndsT<S> ends = make_ends(e, model.bodies);
    std::string what;
    if constexpr (checked) what = out_of_range(e, ends);
    if (!what.empty()) {
      const std::string name = e.segments < 0 ? e.name.substr(0, e.name.rfind(".seg")) : e.name;
      if (reported.insert(e.where.pointer).second)
        diag.error(e.where.file, e.where.pointer,
                   std::string(e.rail ? "rail" : "beam") + " \"" + name + "\": " + what +
                       " is out of the range of double precision (not finite)");
      continue;
    }
    const S modulus_e = e.material.e, modulus_g = e.material.g;
    if (!e.rail) {
      BeamT<S> b;
      b.name = e.name;
      b.group = e.segments < 0 ? e.name.substr(0, e.name.rfind(".seg")) : e.name;
      b.segment = e.segments < 0 ? static_cast<int>(-e.segments) : 0;
      b.ends = ends;
      b.ea = modulus_e * e.section.area;
      b.gj = modulus_g * e.section.torsion_constant;
      b.eiy = modulus_e * e.section.iy;
      b.eiz = modulus_e * e.section.iz;
      b.damping = e.damping;
      b.formulation = e.formulation;
      b.section = e.section;
      b.density = e.material.density;
      model.beams.push_back(b);
    } else {
      RailT<S> r;
      r.name = e.name;
      r.type = e.rail_type;
      r.ends = ends;
      r.gj =
          e.rail_type == RailType::kPrismatic ? S(modulus_g * e.section.torsion_constant) : S(0.0);
      r.eiy = modulus_e * e.section.iy;
      r.eiz = modulus_e * e.section.iz;
      r.min_length = e.min_length.value_or(S(1e-3 * ends.length));
      if (e.travel) r.travel_min = (*e.travel)[0], r.travel_max = (*e.travel)[1];
      r.damping = e.damping;
      r.formulation = e.formulation;
      r.section = e.section;
      r.density = e.material.density;
      model.rails.push_back(r);
    }
  }

  if (diag.size() > errors_before) return std::nullopt;

  // Gravity times a body's mass can overflow where each is finite (a gravity of 1e308 failed at
  // run time, "loads out of the range of double precision", exit 1; an adversarial review).
  for (const BodyT<S>& b : model.bodies)
    if (!b.fixed && !(value_of(b.mass) * values_of(model.gravity)).allFinite()) {
      diag.error(where.file, (where / "gravity").pointer,
                 "gravity times the mass of body \"" + b.name +
                     "\" is out of the range of double precision (not finite)");
      return std::nullopt;
    }

  for (size_t k = 0; k < specs.loads.size(); ++k) {
    LoadT<S> load = specs.loads[k];
    const BodyT<S>& b = model.bodies[load.body];
    load.offset =
        rotation_matrix<S>(b.orientation).transpose() * (specs.load_points[k] - b.position);
    // Every load was accepted, so k is its index in the scene.
    if (!values_of(load.offset).allFinite()) {
      diag.error(where.file, (where / "loads" / k / "point").pointer,
                 "the distance from the body's centre of mass is out of the range of double "
                 "precision (not finite)");
      continue;
    }
    model.loads.push_back(load);
  }
  if (diag.size() > errors_before) return std::nullopt;

  build_joints(specs, elements, model, diag);
  if (diag.size() > errors_before) return std::nullopt;

  model.load_cases = specs.load_cases;
  model.segment_choices = std::move(choices);
  model.finalize();
  if (model.n_free() == 0) {
    diag.error(
        where.file, (where / "bodies").pointer,
        "the scene has no free body: nothing can move (every body is fixed or none is given)");
    return std::nullopt;
  }
  return model;
}

}  // namespace

std::optional<Model> load_scene(const Json& scene, const Where& where, Diagnostics& diag,
                                const std::vector<SegmentChoice>* pinned) {
  return build_scene<double>(scene, where, diag, pinned, {});
}

std::optional<DualModel> load_dual_scene(const Json& scene, const Where& where,
                                         const std::map<std::string, double>& seeds,
                                         const std::vector<SegmentChoice>& pinned,
                                         Diagnostics& diag) {
  return build_scene<HyperDual>(scene, where, diag, &pinned, seeds);
}

}  // namespace beamrail
