// The tangent stiffness on the linear prebuckling path (docs/model.md "Linear buckling"):
//
//   K(lambda) = K(u0 + lambda u1), with the constant loads and lambda times the scaled ones,
//
// which the linear buckling analysis replaces by its linearization K0 + lambda K1 (K1 =
// dK/dlambda at lambda = 0). Where K is not linear in lambda the factor drifts: the element law's
// stiffness changes with the elements' shortening beyond the stress stiffness by a part of
// relative size (r / l)^2, which grows as segments get short beside their section (a 2 m box
// column of 80 x 60 x 4 mm in 256 segments of 7.8 mm: the linearized factor is 3.5 % below
// Euler's load, where the static analysis finds the column stable up to 0.1 % of it). The
// buckling analysis measures this at each factor, phi^T K(lambda) phi / phi^T K0 phi (0 for an
// exact linearization), and warns when it is large. (Solving K(lambda) phi = 0 on the linear path
// instead is no cure: where the true prebuckling path bends away from it, as through a pin's
// hinge beams, that is off the static analysis's limit by as much.)
#pragma once

#include <Eigen/Core>

#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// K(lambda) X (symmetric part, as symmetric_stiffness), from the tangent's blocks: `reference`
// holds the constant loads, `scaled` the loads lambda multiplies, `base` the reference state u0,
// u1 the linear response to the scaled loads.
Eigen::MatrixXd path_stiffness_product(const Model& reference, const Model& scaled, double t,
                                       const Data& base, const Eigen::VectorXd& u1, double lambda,
                                       const Eigen::MatrixXd& x);

}  // namespace beamrail
