// Element end forces for result tables and stress: the force and moment acting ON an element at
// each end (the finite-element end-force convention, the paper's P1 and P2), in the element frame
// carried by the left end, moments about the attachment points. A beam in tension has fx > 0 at
// end 2 and fx < 0 at end 1.
//
// On any scalar: doubles for the tables, hyper-dual numbers for the design sensitivities (a model
// and poses whose numbers carry derivatives).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/model/beam.hpp"
#include "core/model/data.hpp"
#include "core/model/model.hpp"
#include "core/model/rail.hpp"

namespace beamrail {

template <class S>
struct EndForcesT {
  Vec6T<S> end1 = Vec6T<S>::Zero();  // (fx, fy, fz, mx, my, mz) at point 1 [N, N m]
  Vec6T<S> end2 = Vec6T<S>::Zero();  // at point 2
};
using EndForces = EndForcesT<double>;

namespace element_forces_detail {

// Turns the wrenches an element exerts on its bodies into the end forces acting on it.
template <class S>
EndForcesT<S> to_end_forces(const ElementFrames<S>& f, const Vec6T<S>& w1, const Vec6T<S>& w2) {
  const Mat3T<S> et = f.E1.transpose();
  const Vec3T<S> f1 = w1.template head<3>(), f2 = w2.template head<3>();
  EndForcesT<S> out;
  out.end1 << -et * f1, -et * (w1.template tail<3>() - f.R1.cross(f1));
  out.end2 << -et * f2, -et * (w2.template tail<3>() - f.R2.cross(f2));
  return out;
}

// Pose without velocities: end forces are the elastic forces only.
template <class S>
Pose<S> at_rest(const Pose<S>& p) {
  return {p.u, p.A, Vec3T<S>::Zero(), Vec3T<S>::Zero()};
}

}  // namespace element_forces_detail

// End forces of beam `index` / rail `index` in the configuration of the poses (one per body).
template <class S>
EndForcesT<S> beam_end_forces(const ModelT<S>& model, const std::vector<Pose<S>>& pose, int index) {
  using element_forces_detail::at_rest;
  const BeamT<S>& e = model.beams[index];
  const Pose<S> b1 = at_rest(pose[e.ends.body1]), b2 = at_rest(pose[e.ends.body2]);
  Vec6T<S> w1 = Vec6T<S>::Zero(), w2 = Vec6T<S>::Zero();
  beam_wrenches(e, b1, b2, w1, w2);
  return element_forces_detail::to_end_forces(element_frames(e.ends, b1, b2, rotation_measure(e)),
                                              w1, w2);
}
template <class S>
EndForcesT<S> rail_end_forces(const ModelT<S>& model, const std::vector<Pose<S>>& pose, int index) {
  using element_forces_detail::at_rest;
  const RailT<S>& e = model.rails[index];
  const Pose<S> b1 = at_rest(pose[e.ends.body1]), b2 = at_rest(pose[e.ends.body2]);
  Vec6T<S> w1 = Vec6T<S>::Zero(), w2 = Vec6T<S>::Zero();
  bool floored = false;
  rail_wrenches(e, b1, b2, w1, w2, &floored);
  return element_forces_detail::to_end_forces(element_frames(e.ends, b1, b2, rotation_measure(e)),
                                              w1, w2);
}

// In the configuration of data.pose.
inline EndForces beam_end_forces(const Model& model, const Data& data, int index) {
  return beam_end_forces(model, data.pose, index);
}
inline EndForces rail_end_forces(const Model& model, const Data& data, int index) {
  return rail_end_forces(model, data.pose, index);
}

// Largest |N|/S + |My|/Wy + |Mz|/Wz over both ends [Pa]; NaN when a section modulus is unknown.
template <class S>
S end_stress(const SectionPropertiesT<S>& s, const EndForcesT<S>& forces) {
  using std::abs;
  if (!(s.area > 0.0) || !(s.wy > 0.0) || !(s.wz > 0.0))
    return S(std::numeric_limits<double>::quiet_NaN());
  S worst = 0.0;
  for (const Vec6T<S>* p : {&forces.end1, &forces.end2}) {
    const S stress = abs((*p)(0)) / s.area + abs((*p)(4)) / s.wy + abs((*p)(5)) / s.wz;
    if (stress > worst) worst = stress;
  }
  return worst;
}

}  // namespace beamrail
