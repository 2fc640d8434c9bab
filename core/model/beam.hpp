// The beam kernel (docs/model.md "Beams"): wrenches of a massless elastic beam on its two
// bodies, in either force formulation, with stiffness-proportional damping.
#pragma once

#include <type_traits>

#include "core/model/element_kinematics.hpp"
#include "core/model/stiffness.hpp"

namespace beamrail {

// The beam's force law on s = (xi, phi): delta = s - (l, 0, 0, 0, 0, 0); g = K2 delta (energy) or
// p1 = K1 delta, p2 = K2 delta (paper). The coefficients are constants (the length is fixed). The
// beam's numbers are of a scalar P: double, or S itself (design sensitivities).
template <class P, class S>
LocalForces<S> beam_law(const BeamT<P>& beam, const Vec6T<S>& s) {
  const StiffnessBlocks<P> k(beam.ea, beam.gj, beam.eiy, beam.eiz, beam.ends.length);
  Vec6T<S> d = s;
  d(0) = d(0) - beam.ends.length;
  LocalForces<S> out;
  if (beam.formulation == Formulation::kEnergy) {
    out.g = k.k2(d);
  } else {
    out.p1 = k.k1(d);
    out.p2 = k.k2(d);
  }
  out.energy = strain_energy(k, d);
  return out;
}

// Whether a beam's configuration lies outside the range of its law: an angle beyond the limit of
// its rotation measure (angle_limit), or point 2 at or behind point 1 along the axis (compressed
// through zero length: inverted).
inline bool beam_out_of_range(const Beam& beam, const ElementFrames<double>& f) {
  const RotationMeasure measure = rotation_measure(beam);
  return !(f.xi(0) > 0.0) || !(element_angle(f, measure) <= angle_limit(measure));
}

// Adds the beam's wrenches (force, moment about the centre of mass; global) on body 1 and body 2
// to w1 and w2 and returns its strain energy 1/2 delta^T K2 delta [J]. For doubles, sets
// *out_of_range (when given) if the configuration is outside the law's range.
template <class P, class T>
T beam_wrenches(const BeamT<P>& beam, const Pose<T>& b1, const Pose<T>& b2, Vec6T<T>& w1,
                Vec6T<T>& w2, bool* out_of_range = nullptr) {
  const ElementFrames<T> f = element_frames(beam.ends, b1, b2, rotation_measure(beam));
  if constexpr (std::is_same_v<T, double> && std::is_same_v<P, double>)
    if (out_of_range && beam_out_of_range(beam, f)) *out_of_range = true;
  Vec6T<T> s;
  s << f.xi, f.phi;
  const LocalForces<T> law = beam_law(beam, s);
  Vec6T<T> g = Vec6T<T>::Zero();  // gradient dU/d(xi, phi), plus dissipation
  if (beam.formulation == Formulation::kEnergy)
    g = law.g;
  else
    apply_paper_end_wrenches(f, law.p1, law.p2, w1, w2);
  // Damping as the gradient of the dissipation function 1/2 beta rate^T K2 rate: never adds energy.
  if (beam.damping > 0.0) {
    const StiffnessBlocks<P> k(beam.ea, beam.gj, beam.eiy, beam.eiz, beam.ends.length);
    g += beam.damping * k.k2(deformation_rate(f, b1, b2));
  }
  apply_deformation_gradient(f, g, w1, w2);
  return law.energy;
}

// Deformation delta = (u, phi) of a beam: u = xi - (l, 0, 0).
template <class P, class T>
Vec6T<T> beam_deformation(const BeamT<P>& beam, const ElementFrames<T>& f) {
  Vec6T<T> d;
  d << f.xi(0) - beam.ends.length, f.xi(1), f.xi(2), f.phi(0), f.phi(1), f.phi(2);
  return d;
}

}  // namespace beamrail
