// The local stiffness blocks K1 and K2 of docs/model.md (the paper's, with its four sign errors in
// K2 corrected), applied without forming 6 x 6 matrices.
//
// The length enters as a signed value l (rails: the carriage may pass behind point 1). A beam of
// length |l| pointing along -x is the mirror image of one along +x, so the bending-torsion
// couplings carry sign(l) and every other entry uses |l|; for l > 0 this is exactly K1, K2.
#pragma once

#include <cmath>

#include "core/model/types.hpp"

namespace beamrail {

template <class T>
struct StiffnessBlocks {
  T a, t;            // axial E S / L, torsional G Ix / L
  T y3, y2, y1, y0;  // 12 EIy / L^3, 6 s EIy / L^2, 4 EIy / L, 2 EIy / L
  T z3, z2, z1, z0;  // the same with EIz

  // ea, gj, eiy, eiz: rigidities (double, or T itself); length: signed length l with |l| > 0.
  template <class P>
  StiffnessBlocks(const P& ea, const P& gj, const P& eiy, const P& eiz, const T& length) {
    using std::abs;
    const T len = abs(length);
    const T s = length < 0.0 ? T(-1) : T(1);
    a = ea / len;
    t = gj / len;
    y1 = 4.0 * eiy / len;
    y0 = 0.5 * y1;
    y2 = s * 6.0 * eiy / (len * len);
    y3 = 12.0 * eiy / (len * len * len);
    z1 = 4.0 * eiz / len;
    z0 = 0.5 * z1;
    z2 = s * 6.0 * eiz / (len * len);
    z3 = 12.0 * eiz / (len * len * len);
  }

  // K2 d: the end vector at point 2 (forces, moments; left-end frame). The deformation's scalar
  // may differ from the coefficients' (constant coefficients times derivative-carrying values).
  template <class D>
  Vec6T<D> k2(const Vec6T<D>& d) const {
    Vec6T<D> p;
    p << a * d(0), z3 * d(1) - z2 * d(5), y3 * d(2) + y2 * d(4), t * d(3), y2 * d(2) + y1 * d(4),
        -z2 * d(1) + z1 * d(5);
    return p;
  }

  // K1 d: the end vector at point 1.
  template <class D>
  Vec6T<D> k1(const Vec6T<D>& d) const {
    Vec6T<D> p;
    p << -a * d(0), -z3 * d(1) + z2 * d(5), -y3 * d(2) - y2 * d(4), -t * d(3),
        y2 * d(2) + y0 * d(4), -z2 * d(1) + z0 * d(5);
    return p;
  }
};

// A local force law evaluated on the deformation coordinates s = (xi, phi) of an element: the
// energy gradient g = dU/ds (energy formulation) or the end vectors p1 = K1 delta, p2 = K2 delta
// (paper formulation), and the strain energy.
template <class S>
struct LocalForces {
  Vec6T<S> g, p1, p2;
  S energy;
};

// The strain energy 1/2 d^T K2 d.
template <class S, class T>
T strain_energy(const StiffnessBlocks<S>& k, const Vec6T<T>& d) {
  return T(0.5) * d.dot(k.k2(d));
}

// d/d|l| of 1/2 d^T K2(l) d at fixed d, for rigidities without the axial term (rails).
template <class P, class T>
T strain_energy_length_derivative(const P& gj, const P& eiy, const P& eiz, const T& length,
                                  const Vec6T<T>& d) {
  using std::abs;
  const T len = abs(length);
  const T s = length < T(0) ? T(-1) : T(1);
  const T l2 = len * len, l3 = l2 * len, l4 = l3 * len;
  // dU/dL = 1/2 [-36 EI u^2 / L^4 +- 24 s EI u phi / L^3 - 4 EI phi^2 / L^2] per plane, plus
  // torsion.
  const T bend_z = -36.0 * eiz * d(1) * d(1) / l4 + 24.0 * s * eiz * d(1) * d(5) / l3 -
                   4.0 * eiz * d(5) * d(5) / l2;
  const T bend_y = -36.0 * eiy * d(2) * d(2) / l4 - 24.0 * s * eiy * d(2) * d(4) / l3 -
                   4.0 * eiy * d(4) * d(4) / l2;
  const T twist = -gj * d(3) * d(3) / l2;
  return T(0.5) * (bend_z + bend_y + twist);
}

}  // namespace beamrail
