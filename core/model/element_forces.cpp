#include "core/model/element_forces.hpp"

#include <cmath>
#include <limits>

#include "core/model/beam.hpp"
#include "core/model/rail.hpp"

namespace beamrail {
namespace {

// Turns the wrenches an element exerts on its bodies into the end forces acting on it.
EndForces to_end_forces(const ElementFrames<double>& f, const Vec6& w1, const Vec6& w2) {
  const Mat3 et = f.E1.transpose();
  EndForces out;
  out.end1 << -et * w1.head<3>(), -et * (w1.tail<3>() - f.R1.cross(w1.head<3>()));
  out.end2 << -et * w2.head<3>(), -et * (w2.tail<3>() - f.R2.cross(w2.head<3>()));
  return out;
}

// Pose without velocities: end forces are the elastic forces only.
Pose<double> at_rest(const Pose<double>& p) { return {p.u, p.A, Vec3::Zero(), Vec3::Zero()}; }

}  // namespace

EndForces beam_end_forces(const Model& model, const Data& data, int index) {
  const Beam& e = model.beams[index];
  const Pose<double> b1 = at_rest(data.pose[e.ends.body1]), b2 = at_rest(data.pose[e.ends.body2]);
  Vec6 w1 = Vec6::Zero(), w2 = Vec6::Zero();
  beam_wrenches(e, b1, b2, w1, w2);
  return to_end_forces(element_frames(e.ends, b1, b2, rotation_measure(e)), w1, w2);
}

EndForces rail_end_forces(const Model& model, const Data& data, int index) {
  const Rail& e = model.rails[index];
  const Pose<double> b1 = at_rest(data.pose[e.ends.body1]), b2 = at_rest(data.pose[e.ends.body2]);
  Vec6 w1 = Vec6::Zero(), w2 = Vec6::Zero();
  bool floored = false;
  rail_wrenches(e, b1, b2, w1, w2, &floored);
  return to_end_forces(element_frames(e.ends, b1, b2, rotation_measure(e)), w1, w2);
}

double end_stress(const SectionProperties& s, const EndForces& forces) {
  if (!(s.area > 0.0) || !(s.wy > 0.0) || !(s.wz > 0.0))
    return std::numeric_limits<double>::quiet_NaN();
  double worst = 0.0;
  for (const Vec6* p : {&forces.end1, &forces.end2})
    worst = std::max(
        worst, std::abs((*p)(0)) / s.area + std::abs((*p)(4)) / s.wy + std::abs((*p)(5)) / s.wz);
  return worst;
}

}  // namespace beamrail
