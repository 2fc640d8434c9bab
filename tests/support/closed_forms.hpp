// Closed forms the tests compare with.
#pragma once

#include <Eigen/Eigenvalues>
#include <array>

namespace beamrail::testing {

// Angular frequencies^2 of the 2 x 2 bending problem of a tip body on a massless cantilever of
// length l and bending stiffness ei, the body's centre of mass lying e beyond the tip (mass m,
// rotary inertia j about its centre): K = EI [12/l^3, -6/l^2; -6/l^2, 4/l], M = [m, m e; m e,
// J + m e^2] (the sign of the coupling terms, which differs between bending in y about z and in
// z about y, does not change the result).
inline std::array<double, 2> bending_pair(double ei, double l, double m, double j, double e) {
  Eigen::Matrix2d k, mm;
  k << 12 * ei / (l * l * l), -6 * ei / (l * l), -6 * ei / (l * l), 4 * ei / l;
  mm << m, m * e, m * e, j + m * e * e;
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix2d> eig(k, mm);
  return {eig.eigenvalues()(0), eig.eigenvalues()(1)};
}

}  // namespace beamrail::testing
