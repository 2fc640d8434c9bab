// The element kinds in one place. Each kind (beam, rail, joint) has a traits struct that names it,
// finds its elements in the model and the two bodies of each, and evaluates what the analyses and
// outputs ask of an element: its wrenches, its configuration tangent, its end forces, its mass and
// the few facts in which the kinds differ (a rail's floored length, a joint's gap).
//
// for_each_element_kind and for_each_element visit the kinds in one fixed order, beams, rails,
// joints: the order of the wrench sums, of the tangent pattern and of the element forces tables.
// The list is a compile-time tuple and the visitors are generic lambdas, so each kind's loop runs
// over its own contiguous array as a hand-written loop would, without virtual calls.
//
// Adding a kind: its element struct and container in ModelT (model.hpp), its kernel in a file of
// its own, a traits struct here and its name in ElementKinds, its numbers in model_numbers.hpp,
// its JSON in the scene reader, a sampler in tests/core/model/element_kinds_test.cpp
// (docs/model.md "Adding an element kind").
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "core/model/beam.hpp"
#include "core/model/element_forces.hpp"
#include "core/model/element_tangent.hpp"
#include "core/model/joint.hpp"
#include "core/model/joint_forces.hpp"
#include "core/model/model.hpp"
#include "core/model/rail.hpp"

namespace beamrail {

// Every kind's traits provide:
//   kName                      the kind as tables, messages and JSON name it ("beam")
//   kCountedWhenNone           whether the run's summary and `beamrail check` give its count
//                              (kName + "s") when the scene has none
//   elements(model)            its array in the model (const or not)
//   body1(e), body2(e)         the indices of its two bodies
//   point1(e), point2(e)       its attachment points in body axes, from the centres [m]
//   wrenches(e, b1, b2, w1, w2, floored, out_of_range)
//                              adds its wrenches on its bodies and returns its energy [J]; sets
//                              *floored (never null) and, for doubles, *out_of_range (when given)
//   kFloors                    whether wrenches can report a floored state (Data::rail_floored)
//   damping(e)                 its stiffness-proportional damping [s] (0: none)
//   configuration_jacobian(e, p1, p2)
//                              d(w1, w2)/d(dc1, dtheta1, dc2, dtheta2) without damping terms
//   end_forces(model, pose, i) its end forces (core/model/element_forces.hpp)
//   length(e), mass(e)         its length at set-up [m] (0 without one), its mass [kg]
//   holds_all_six(e)           whether it resists all six relative motions of its bodies
//   stress(e, forces)          the largest end stress [Pa]; NaN without a section
//   gap(e, b1, b2)             the distance |p2 - p1| a joint keeps zero [m]; NaN for others
//   same_element(a, b)         whether a and b, of two designs' models, are the same element
//                              (the same name; a joint the same type)
//   named(model, name, end)    the index of the element called `name` (-1: none) whose end
//                              `end` (1 or 2) is that of the scene element of that name

struct BeamKind {
  static constexpr const char* kName = "beam";
  static constexpr bool kCountedWhenNone = true;
  static constexpr bool kFloors = false;

  template <class M>
  static auto& elements(M& model) {
    return model.beams;
  }
  template <class S>
  static int body1(const BeamT<S>& e) {
    return e.ends.body1;
  }
  template <class S>
  static int body2(const BeamT<S>& e) {
    return e.ends.body2;
  }
  template <class S>
  static const Vec3T<S>& point1(const BeamT<S>& e) {
    return e.ends.r1;
  }
  template <class S>
  static const Vec3T<S>& point2(const BeamT<S>& e) {
    return e.ends.r2;
  }

  template <class P, class T>
  static T wrenches(const BeamT<P>& e, const Pose<T>& b1, const Pose<T>& b2, Vec6T<T>& w1,
                    Vec6T<T>& w2, bool* /*floored*/, bool* out_of_range) {
    return beam_wrenches(e, b1, b2, w1, w2, out_of_range);
  }
  template <class S>
  static S damping(const BeamT<S>& e) {
    return e.damping;
  }
  static Mat12 configuration_jacobian(const Beam& e, const Pose<double>& p1,
                                      const Pose<double>& p2) {
    const RotationMeasure measure = rotation_measure(e);
    return beamrail::configuration_jacobian(element_frames(e.ends, p1, p2, measure), e.formulation,
                                            measure,
                                            [&e](const Vec6T<Ad6>& s) { return beam_law(e, s); });
  }
  template <class S>
  static EndForcesT<S> end_forces(const ModelT<S>& model, const std::vector<Pose<S>>& pose,
                                  int index) {
    return beam_end_forces(model, pose, index);
  }

  template <class S>
  static S length(const BeamT<S>& e) {
    return e.ends.length;
  }
  template <class S>
  static S mass(const BeamT<S>& e) {
    return e.density * e.section.area * e.ends.length;
  }
  static bool holds_all_six(const Beam&) { return true; }
  template <class S>
  static S stress(const BeamT<S>& e, const EndForcesT<S>& forces) {
    return end_stress(e.section, forces);
  }
  static bool same_element(const Beam& a, const Beam& b) { return a.name == b.name; }
  static double gap(const Beam&, const Pose<double>&, const Pose<double>&) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  // A scene beam split into segments keeps its scene name as the segments' group: the segment
  // that holds end `end` (1 or 2) of the scene beam.
  template <class S>
  static int named(const ModelT<S>& model, const std::string& name, int end) {
    int found = -1;
    for (size_t i = 0; i < model.beams.size(); ++i) {
      const BeamT<S>& b = model.beams[i];
      if (b.group != name) continue;
      if (found < 0 || (end == 2 && b.segment > model.beams[found].segment))
        found = static_cast<int>(i);
      if (end == 1 && b.segment <= 1) found = static_cast<int>(i);
    }
    return found;
  }
};

// The index of the element of `elements` named `name`, -1 if none.
template <class E>
int index_named(const std::vector<E>& elements, const std::string& name) {
  for (size_t i = 0; i < elements.size(); ++i)
    if (elements[i].name == name) return static_cast<int>(i);
  return -1;
}

struct RailKind {
  static constexpr const char* kName = "rail";
  static constexpr bool kCountedWhenNone = true;
  // |l| at min_length: Data::rail_floored and the static and transient warnings.
  static constexpr bool kFloors = true;

  template <class M>
  static auto& elements(M& model) {
    return model.rails;
  }
  template <class S>
  static int body1(const RailT<S>& e) {
    return e.ends.body1;
  }
  template <class S>
  static int body2(const RailT<S>& e) {
    return e.ends.body2;
  }
  template <class S>
  static const Vec3T<S>& point1(const RailT<S>& e) {
    return e.ends.r1;
  }
  template <class S>
  static const Vec3T<S>& point2(const RailT<S>& e) {
    return e.ends.r2;
  }

  template <class P, class T>
  static T wrenches(const RailT<P>& e, const Pose<T>& b1, const Pose<T>& b2, Vec6T<T>& w1,
                    Vec6T<T>& w2, bool* floored, bool* out_of_range) {
    return rail_wrenches(e, b1, b2, w1, w2, floored, out_of_range);
  }
  template <class S>
  static S damping(const RailT<S>& e) {
    return e.damping;
  }
  static Mat12 configuration_jacobian(const Rail& e, const Pose<double>& p1,
                                      const Pose<double>& p2) {
    const RotationMeasure measure = rotation_measure(e);
    return beamrail::configuration_jacobian(element_frames(e.ends, p1, p2, measure), e.formulation,
                                            measure, [&e](const Vec6T<Ad6>& s) {
                                              bool floored = false;
                                              return rail_law(e, s, &floored);
                                            });
  }
  template <class S>
  static EndForcesT<S> end_forces(const ModelT<S>& model, const std::vector<Pose<S>>& pose,
                                  int index) {
    return rail_end_forces(model, pose, index);
  }

  template <class S>
  static S length(const RailT<S>& e) {
    return e.ends.length;
  }
  template <class S>
  static S mass(const RailT<S>& e) {
    return e.density * e.section.area * e.ends.length;
  }
  // The carriage slides: no axial stiffness.
  static bool holds_all_six(const Rail&) { return false; }
  template <class S>
  static S stress(const RailT<S>& e, const EndForcesT<S>& forces) {
    return end_stress(e.section, forces);
  }
  static bool same_element(const Rail& a, const Rail& b) { return a.name == b.name; }
  static double gap(const Rail&, const Pose<double>&, const Pose<double>&) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  template <class S>
  static int named(const ModelT<S>& model, const std::string& name, int /*end*/) {
    return index_named(model.rails, name);
  }
};

struct JointKind {
  static constexpr const char* kName = "joint";
  // Joints came after the summary's format: a scene without them summarizes as before.
  static constexpr bool kCountedWhenNone = false;
  static constexpr bool kFloors = false;

  template <class M>
  static auto& elements(M& model) {
    return model.joints;
  }
  template <class S>
  static int body1(const JointT<S>& e) {
    return e.body1;
  }
  template <class S>
  static int body2(const JointT<S>& e) {
    return e.body2;
  }
  template <class S>
  static const Vec3T<S>& point1(const JointT<S>& e) {
    return e.r1;
  }
  template <class S>
  static const Vec3T<S>& point2(const JointT<S>& e) {
    return e.r2;
  }

  // A joint's law covers every configuration: it is never out of range.
  template <class P, class T>
  static T wrenches(const JointT<P>& e, const Pose<T>& b1, const Pose<T>& b2, Vec6T<T>& w1,
                    Vec6T<T>& w2, bool* /*floored*/, bool* /*out_of_range*/) {
    return joint_wrenches(e, b1, b2, w1, w2);
  }
  template <class S>
  static S damping(const JointT<S>&) {
    return S(0.0);
  }
  // Forward AD through the whole kernel: a joint's kernel is a few cross products, and it has no
  // local law for the closed form of configuration_jacobian.
  static Mat12 configuration_jacobian(const Joint& e, const Pose<double>& p1,
                                      const Pose<double>& p2) {
    const auto kernel = [&e](const Pose<Ad12>& b1, const Pose<Ad12>& b2, Vec6T<Ad12>& w1,
                             Vec6T<Ad12>& w2) { joint_wrenches(e, b1, b2, w1, w2); };
    return element_jacobian(seed_configuration(p1, 0), seed_configuration(p2, 6), kernel);
  }
  template <class S>
  static EndForcesT<S> end_forces(const ModelT<S>& model, const std::vector<Pose<S>>& pose,
                                  int index) {
    return joint_end_forces(model, pose, index);
  }

  template <class S>
  static S length(const JointT<S>&) {
    return S(0.0);
  }
  template <class S>
  static S mass(const JointT<S>&) {
    return S(0.0);
  }
  // Spherical and revolute joints leave rotations free (docs/model.md "Joints").
  static bool holds_all_six(const Joint& e) { return e.type == JointType::kFixed; }
  template <class S>
  static S stress(const JointT<S>&, const EndForcesT<S>&) {
    return S(std::numeric_limits<double>::quiet_NaN());
  }
  static bool same_element(const Joint& a, const Joint& b) {
    return a.name == b.name && a.type == b.type;
  }
  static double gap(const Joint& e, const Pose<double>& b1, const Pose<double>& b2) {
    return joint_gap(e, b1, b2).norm();
  }
  template <class S>
  static int named(const ModelT<S>& model, const std::string& name, int /*end*/) {
    return index_named(model.joints, name);
  }
};

// The kinds, in the order every visitor takes them.
using ElementKinds = std::tuple<BeamKind, RailKind, JointKind>;

namespace element_kinds_detail {
template <class Kind, class... Kinds>
constexpr int index_of(std::tuple<Kinds...>*) {
  int index = 0, found = -1;
  ((std::is_same_v<Kind, Kinds> ? (found = index, ++index) : ++index), ...);
  return found;
}
}  // namespace element_kinds_detail

// The position of Kind in ElementKinds.
template <class Kind>
inline constexpr int kElementKindIndex =
    element_kinds_detail::index_of<Kind>(static_cast<ElementKinds*>(nullptr));

// Calls f(kind) with a value of each kind's traits type, in the order of ElementKinds.
template <class F>
void for_each_element_kind(F&& f) {
  std::apply([&f](auto... kind) { (f(kind), ...); }, ElementKinds{});
}

// Calls f(kind, element, index) for every element of `model` (const or not), kind by kind in the
// order of ElementKinds, each kind's elements in the order of its array.
template <class M, class F>
void for_each_element(M& model, F&& f) {
  for_each_element_kind([&](auto kind) {
    auto& elements = decltype(kind)::elements(model);
    for (size_t i = 0; i < elements.size(); ++i) f(kind, elements[i], static_cast<int>(i));
  });
}

// f(kind, element, index) for the element `ref` names; every kind's call must return one type.
template <class M, class F>
decltype(auto) visit_element(M& model, ElementRef ref, F&& f) {
  using Result = decltype(f(BeamKind{}, BeamKind::elements(model)[0], 0));
  if constexpr (std::is_void_v<Result>) {
    for_each_element_kind([&](auto kind) {
      if (kElementKindIndex<decltype(kind)> == ref.kind)
        f(kind, decltype(kind)::elements(model)[ref.index], ref.index);
    });
  } else {
    Result out{};
    for_each_element_kind([&](auto kind) {
      if (kElementKindIndex<decltype(kind)> == ref.kind)
        out = f(kind, decltype(kind)::elements(model)[ref.index], ref.index);
    });
    return out;
  }
}

// Whether the models of two designs hold the same elements: as many of each kind, each the same
// element (same_element) as its counterpart.
template <class S>
bool same_elements(const ModelT<S>& a, const ModelT<S>& b) {
  bool same = true;
  for_each_element_kind([&](auto kind) {
    using Kind = decltype(kind);
    const auto &ea = Kind::elements(a), &eb = Kind::elements(b);
    same = same && ea.size() == eb.size();
    for (size_t i = 0; same && i < ea.size(); ++i) same = Kind::same_element(ea[i], eb[i]);
  });
  return same;
}

// The element called `name` in the scene (element names are unique over the kinds); for a scene
// beam split into segments, the segment that holds its end `end` (1 or 2).
template <class S>
std::optional<ElementRef> find_element(const ModelT<S>& model, const std::string& name,
                                       int end = 1) {
  std::optional<ElementRef> out;
  for_each_element_kind([&](auto kind) {
    if (out) return;
    const int index = decltype(kind)::named(model, name, end);
    if (index >= 0) out = ElementRef{kElementKindIndex<decltype(kind)>, index};
  });
  return out;
}

}  // namespace beamrail
