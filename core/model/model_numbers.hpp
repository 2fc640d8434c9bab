// Every number of a model, visited in lockstep over models of the same scene: a model on another
// scalar built number by number (the design sensitivities' dual model from a model and its
// derivative). What is not a number (names, indices, flags, time functions, the pattern) is the
// first model's.
#pragma once

#include <utility>

#include "core/model/model.hpp"

namespace beamrail {
namespace model_numbers {

// out = f(in...) for a scalar, coefficient by coefficient for an Eigen matrix.
template <class F, class O, class... I>
void number(F& f, O& out, const I&... in) {
  if constexpr (requires { O::RowsAtCompileTime; }) {
    for (Eigen::Index k = 0; k < out.size(); ++k) out.data()[k] = f(in.data()[k]...);
  } else {
    out = f(in...);
  }
}

template <class F, class T, class S0, class... S>
ElementEndsT<T> ends(F& f, const ElementEndsT<S0>& e0, const ElementEndsT<S>&... e) {
  ElementEndsT<T> o;
  o.body1 = e0.body1, o.body2 = e0.body2;
  number(f, o.r1, e0.r1, e.r1...);
  number(f, o.r2, e0.r2, e.r2...);
  number(f, o.frame1, e0.frame1, e.frame1...);
  number(f, o.frame2, e0.frame2, e.frame2...);
  number(f, o.centre_offset, e0.centre_offset, e.centre_offset...);
  number(f, o.length, e0.length, e.length...);
  return o;
}

template <class F, class T, class S0, class... S>
SectionPropertiesT<T> section(F& f, const SectionPropertiesT<S0>& s0,
                              const SectionPropertiesT<S>&... s) {
  SectionPropertiesT<T> o;
  number(f, o.area, s0.area, s.area...);
  number(f, o.torsion_constant, s0.torsion_constant, s.torsion_constant...);
  number(f, o.iy, s0.iy, s.iy...);
  number(f, o.iz, s0.iz, s.iz...);
  number(f, o.wy, s0.wy, s.wy...);
  number(f, o.wz, s0.wz, s.wz...);
  return o;
}

}  // namespace model_numbers

// The model on scalar T whose every number is f(the numbers of `first` and `others` at the same
// place); the models must be of one scene (the same bodies, elements and loads).
template <class T, class F, class S0, class... S>
ModelT<T> zip_numbers(F&& f, const ModelT<S0>& first, const ModelT<S>&... others) {
  using model_numbers::number;
  ModelT<T> out;
  out.bodies.resize(first.bodies.size());
  for (size_t i = 0; i < first.bodies.size(); ++i) {
    const BodyT<S0>& b0 = first.bodies[i];
    BodyT<T>& o = out.bodies[i];
    o.name = b0.name, o.fixed = b0.fixed, o.generated = b0.generated;
    o.driven = b0.driven, o.motion = b0.motion;
    o.free_index = b0.free_index;
    number(f, o.mass, b0.mass, others.bodies[i].mass...);
    number(f, o.inertia, b0.inertia, others.bodies[i].inertia...);
    number(f, o.inertia_inverse, b0.inertia_inverse, others.bodies[i].inertia_inverse...);
    number(f, o.position, b0.position, others.bodies[i].position...);
    number(f, o.orientation, b0.orientation, others.bodies[i].orientation...);
    number(f, o.velocity, b0.velocity, others.bodies[i].velocity...);
    number(f, o.angular_velocity, b0.angular_velocity, others.bodies[i].angular_velocity...);
    number(f, o.declared_mass, b0.declared_mass, others.bodies[i].declared_mass...);
  }
  out.beams.resize(first.beams.size());
  for (size_t i = 0; i < first.beams.size(); ++i) {
    const BeamT<S0>& e0 = first.beams[i];
    BeamT<T>& o = out.beams[i];
    o.name = e0.name, o.formulation = e0.formulation, o.group = e0.group, o.segment = e0.segment;
    o.ends = model_numbers::ends<F, T>(f, e0.ends, others.beams[i].ends...);
    o.section = model_numbers::section<F, T>(f, e0.section, others.beams[i].section...);
    number(f, o.ea, e0.ea, others.beams[i].ea...);
    number(f, o.gj, e0.gj, others.beams[i].gj...);
    number(f, o.eiy, e0.eiy, others.beams[i].eiy...);
    number(f, o.eiz, e0.eiz, others.beams[i].eiz...);
    number(f, o.damping, e0.damping, others.beams[i].damping...);
    number(f, o.density, e0.density, others.beams[i].density...);
  }
  out.rails.resize(first.rails.size());
  for (size_t i = 0; i < first.rails.size(); ++i) {
    const RailT<S0>& e0 = first.rails[i];
    RailT<T>& o = out.rails[i];
    o.name = e0.name, o.type = e0.type, o.formulation = e0.formulation;
    o.ends = model_numbers::ends<F, T>(f, e0.ends, others.rails[i].ends...);
    o.section = model_numbers::section<F, T>(f, e0.section, others.rails[i].section...);
    number(f, o.gj, e0.gj, others.rails[i].gj...);
    number(f, o.eiy, e0.eiy, others.rails[i].eiy...);
    number(f, o.eiz, e0.eiz, others.rails[i].eiz...);
    number(f, o.min_length, e0.min_length, others.rails[i].min_length...);
    number(f, o.travel_min, e0.travel_min, others.rails[i].travel_min...);
    number(f, o.travel_max, e0.travel_max, others.rails[i].travel_max...);
    number(f, o.damping, e0.damping, others.rails[i].damping...);
    number(f, o.density, e0.density, others.rails[i].density...);
  }
  out.joints.resize(first.joints.size());
  for (size_t i = 0; i < first.joints.size(); ++i) {
    const JointT<S0>& j0 = first.joints[i];
    JointT<T>& o = out.joints[i];
    o.name = j0.name, o.type = j0.type, o.body1 = j0.body1, o.body2 = j0.body2;
    number(f, o.r1, j0.r1, others.joints[i].r1...);
    number(f, o.r2, j0.r2, others.joints[i].r2...);
    number(f, o.frame1, j0.frame1, others.joints[i].frame1...);
    number(f, o.frame2, j0.frame2, others.joints[i].frame2...);
    number(f, o.lever1, j0.lever1, others.joints[i].lever1...);
    number(f, o.lever2, j0.lever2, others.joints[i].lever2...);
    number(f, o.relative_compliance, j0.relative_compliance,
           others.joints[i].relative_compliance...);
    number(f, o.k_force, j0.k_force, others.joints[i].k_force...);
    number(f, o.k_moment, j0.k_moment, others.joints[i].k_moment...);
  }
  out.loads.resize(first.loads.size());
  for (size_t i = 0; i < first.loads.size(); ++i) {
    const LoadT<S0>& l0 = first.loads[i];
    LoadT<T>& o = out.loads[i];
    o.kind = l0.kind, o.body = l0.body, o.follows = l0.follows;
    o.time.type = static_cast<typename TimeFunctionT<T>::Type>(l0.time.type);
    number(f, o.time.at, l0.time.at, others.loads[i].time.at...);
    number(f, o.time.from, l0.time.from, others.loads[i].time.from...);
    number(f, o.time.to, l0.time.to, others.loads[i].time.to...);
    number(f, o.time.frequency, l0.time.frequency, others.loads[i].time.frequency...);
    number(f, o.time.phase, l0.time.phase, others.loads[i].time.phase...);
    o.time.t.resize(l0.time.t.size());
    for (size_t k = 0; k < l0.time.t.size(); ++k)
      number(f, o.time.t[k], l0.time.t[k], others.loads[i].time.t[k]...);
    o.time.v.resize(l0.time.v.size());
    for (size_t k = 0; k < l0.time.v.size(); ++k)
      number(f, o.time.v[k], l0.time.v[k], others.loads[i].time.v[k]...);
    o.load_case = l0.load_case;
    number(f, o.offset, l0.offset, others.loads[i].offset...);
    number(f, o.value, l0.value, others.loads[i].value...);
  }
  number(f, out.gravity, first.gravity, others.gravity...);
  out.load_cases = first.load_cases;
  out.segment_choices = first.segment_choices;
  out.free_bodies = first.free_bodies;
  out.driven_bodies = first.driven_bodies;
  out.n_states = first.n_states;
  out.n_dofs = first.n_dofs;
  out.pattern = first.pattern;
  return out;
}

}  // namespace beamrail
