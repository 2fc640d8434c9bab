// The rail kernel (DESIGN.md §1, paper section 2): a beam fixed to body 1 along its local x on
// which body 2 slides. Its deformable length l is the current axial coordinate of point 2 in the
// left-end frame, floored in magnitude at min_length; it has no axial stiffness, and a cylindrical
// rail has no torsional stiffness either.
#pragma once

#include <cmath>

#include "core/model/element_kinematics.hpp"
#include "core/model/stiffness.hpp"

namespace beamrail {

// Current deformable length: l = xi_x with |l| >= min_length. Sets *floored when the floor acts.
template <class T>
T rail_length(const Rail& rail, const ElementFrames<T>& f, bool* floored) {
  using std::abs;
  const T l = f.xi(0);
  if (abs(l) >= rail.min_length) {
    *floored = false;
    return l;
  }
  *floored = true;
  return T(l < T(0) ? -rail.min_length : rail.min_length);
}

// Deformation of a rail: no axial part (the carriage slides).
template <class T>
Vec6T<T> rail_deformation(const ElementFrames<T>& f) {
  Vec6T<T> d;
  d << T(0), f.xi(1), f.xi(2), f.phi(0), f.phi(1), f.phi(2);
  return d;
}

// Adds the rail's wrenches on body 1 (the rail) and body 2 (the carriage) to w1 and w2 and returns
// the strain energy 1/2 delta^T K2(l) delta [J]. Sets *floored when |l| hit min_length.
template <class T>
T rail_wrenches(const Rail& rail, const Pose<T>& b1, const Pose<T>& b2, Vec6T<T>& w1, Vec6T<T>& w2,
                bool* floored) {
  const ElementFrames<T> f =
      element_frames(rail.ends, b1, b2, rail.type == RailType::kCylindrical);
  const T l = rail_length(rail, f, floored);
  const StiffnessBlocks<T> k(0.0, rail.gj, rail.eiy, rail.eiz, l);
  const Vec6T<T> d = rail_deformation(f);
  Vec6T<T> g = Vec6T<T>::Zero();
  if (rail.formulation == Formulation::kEnergy) {
    g = k.k2(d);
    // U depends on xi_x through l: the configurational force along the rail.
    if (!*floored) {
      const T s = l < T(0) ? T(-1) : T(1);
      g(0) = s * strain_energy_length_derivative(rail.gj, rail.eiy, rail.eiz, l, d);
    }
  } else {
    apply_paper_end_wrenches(f, k.k1(d), k.k2(d), w1, w2);
  }
  if (rail.damping > 0.0) g += rail.damping * k.k2(deformation_rate(f, b1, b2));
  apply_deformation_gradient(f, g, w1, w2);
  return strain_energy(k, d);
}

}  // namespace beamrail
