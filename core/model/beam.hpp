// The beam kernel (DESIGN.md §1, paper section 1): wrenches of a massless elastic beam on its two
// bodies, in either force formulation, with stiffness-proportional damping.
#pragma once

#include "core/model/element_kinematics.hpp"
#include "core/model/stiffness.hpp"

namespace beamrail {

// Deformation delta = (u, phi) of a beam: u = xi - (l, 0, 0).
template <class T>
Vec6T<T> beam_deformation(const Beam& beam, const ElementFrames<T>& f) {
  Vec6T<T> d;
  d << f.xi(0) - beam.ends.length, f.xi(1), f.xi(2), f.phi(0), f.phi(1), f.phi(2);
  return d;
}

// Adds the beam's wrenches (force, moment about the centre of mass; global) on body 1 and body 2
// to w1 and w2 and returns its strain energy 1/2 delta^T K2 delta [J].
template <class T>
T beam_wrenches(const Beam& beam, const Pose<T>& b1, const Pose<T>& b2, Vec6T<T>& w1, Vec6T<T>& w2) {
  const ElementFrames<T> f = element_frames(beam.ends, b1, b2);
  const StiffnessBlocks<T> k(beam.ea, beam.gj, beam.eiy, beam.eiz, T(beam.ends.length));
  const Vec6T<T> d = beam_deformation(beam, f);
  Vec6T<T> g = Vec6T<T>::Zero();  // gradient dU/d(xi, phi), plus dissipation
  if (beam.formulation == Formulation::kEnergy) {
    g = k.k2(d);
  } else {
    apply_paper_end_wrenches(f, k.k1(d), k.k2(d), w1, w2);
  }
  // Damping as the gradient of the dissipation function 1/2 beta rate^T K2 rate: never adds energy.
  if (beam.damping > 0.0) g += beam.damping * k.k2(deformation_rate(f, b1, b2));
  apply_deformation_gradient(f, g, w1, w2);
  return strain_energy(k, d);
}

}  // namespace beamrail
