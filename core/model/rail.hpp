// The rail kernel (docs/model.md "Rails"): a beam fixed to body 1 along its local x on
// which body 2 slides. Its deformable length l is the current axial coordinate of point 2 in the
// left-end frame, floored in magnitude at min_length; it has no axial stiffness, and a cylindrical
// rail has no torsional stiffness either.
#pragma once

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "core/model/element_kinematics.hpp"
#include "core/model/stiffness.hpp"

namespace beamrail {

// Current deformable length from the axial coordinate x = xi_x: l = x with |l| >= min_length.
// Sets *floored when the floor acts.
// The rail's numbers are of a scalar P: double, or T itself (design sensitivities).
template <class P, class T>
T rail_length(const RailT<P>& rail, const T& x, bool* floored) {
  using std::abs;
  if (abs(x) >= rail.min_length) {
    *floored = false;
    return x;
  }
  *floored = true;
  return T(x < 0.0 ? -rail.min_length : rail.min_length);
}

// The stiffness of a cantilever of length l (rail_length) at axial coordinate x. Its
// bending-rotation couplings carry the direction sign(l) (stiffness.hpp); inside the floor that
// sign runs linearly from -1 to 1 (x / min_length) instead of jumping at x = 0, so that forces
// and strain energy stay continuous while the carriage passes point 1 (a jump of the energy there
// made the energy law gain energy at every pass).
template <class P, class T>
StiffnessBlocks<T> rail_stiffness(const RailT<P>& rail, const T& x, const T& l, bool floored) {
  StiffnessBlocks<T> k(P(0.0), rail.gj, rail.eiy, rail.eiz, l);
  if (floored) {
    const T sign = x / rail.min_length;
    const P m2 = rail.min_length * rail.min_length;
    k.y2 = sign * (6.0 * rail.eiy / m2);
    k.z2 = sign * (6.0 * rail.eiz / m2);
  }
  return k;
}

// The rail's force law on s = (xi, phi): delta = (0, xi_y, xi_z, phi) with the stiffness of a
// cantilever of length l = xi_x. Energy: g = dU/ds, whose first entry is the configurational force
// dU/dl along the rail (while l is floored, only the blended sign of the couplings depends on x);
// paper: p1 = K1(l) delta, p2 = K2(l) delta.
template <class P, class S>
LocalForces<S> rail_law(const RailT<P>& rail, const Vec6T<S>& s, bool* floored) {
  const S l = rail_length(rail, S(s(0)), floored);
  const StiffnessBlocks<S> k = rail_stiffness(rail, S(s(0)), l, *floored);
  Vec6T<S> d = s;
  d(0) = S(0.0);
  LocalForces<S> out;
  if (rail.formulation == Formulation::kEnergy) {
    out.g = k.k2(d);
    if (*floored) {
      // U = ... + sign (6 / m^2) (EIy d2 d4 - EIz d1 d5) with sign = x / m.
      const P m3 = rail.min_length * rail.min_length * rail.min_length;
      out.g(0) = 6.0 * (rail.eiy * d(2) * d(4) - rail.eiz * d(1) * d(5)) / m3;
    } else {
      out.g(0) = (l < 0.0 ? S(-1.0) : S(1.0)) *
                 strain_energy_length_derivative(rail.gj, rail.eiy, rail.eiz, l, d);
    }
  } else {
    out.p1 = k.k1(d);
    out.p2 = k.k2(d);
  }
  out.energy = strain_energy(k, d);
  return out;
}

// The largest angle of a rail that counts as deformation (a cylindrical rail's twist is free).
inline double rail_angle(const Rail& rail, const ElementFrames<double>& f) {
  return element_angle(f, rotation_measure(rail));
}

// Whether a rail's configuration lies outside the range of its law: an angle beyond
// kElementAngleLimit, or the carriage outside the rail's travel.
inline bool rail_out_of_range(const Rail& rail, const ElementFrames<double>& f) {
  return !(rail_angle(rail, f) <= kElementAngleLimit) ||
         !(f.xi(0) >= rail.travel_min && f.xi(0) <= rail.travel_max);
}

// Adds the rail's wrenches on body 1 (the rail) and body 2 (the carriage) to w1 and w2 and returns
// the strain energy 1/2 delta^T K2(l) delta [J]. Sets *floored when |l| hit min_length; for
// doubles, sets *out_of_range (when given) if the configuration is outside the law's range.
template <class P, class T>
T rail_wrenches(const RailT<P>& rail, const Pose<T>& b1, const Pose<T>& b2, Vec6T<T>& w1,
                Vec6T<T>& w2, bool* floored, bool* out_of_range = nullptr) {
  const ElementFrames<T> f = element_frames(rail.ends, b1, b2, rotation_measure(rail));
  if constexpr (std::is_same_v<T, double> && std::is_same_v<P, double>)
    if (out_of_range && rail_out_of_range(rail, f)) *out_of_range = true;
  Vec6T<T> s;
  s << f.xi, f.phi;
  const LocalForces<T> law = rail_law(rail, s, floored);
  Vec6T<T> g = Vec6T<T>::Zero();
  if (rail.formulation == Formulation::kEnergy)
    g = law.g;
  else
    apply_paper_end_wrenches(f, law.p1, law.p2, w1, w2);
  if (rail.damping > 0.0) {
    const StiffnessBlocks<T> k =
        rail_stiffness(rail, f.xi(0), rail_length(rail, f.xi(0), floored), *floored);
    g += rail.damping * k.k2(deformation_rate(f, b1, b2));
  }
  apply_deformation_gradient(f, g, w1, w2);
  return law.energy;
}

// Deformation of a rail: no axial part (the carriage slides).
template <class T>
Vec6T<T> rail_deformation(const ElementFrames<T>& f) {
  Vec6T<T> d;
  d << T(0), f.xi(1), f.xi(2), f.phi(0), f.phi(1), f.phi(2);
  return d;
}

}  // namespace beamrail
