// How much a small motion of the bodies deforms the elements: the test that tells a rigid-body or
// mechanism mode (it deforms no element) from an elastic one, whatever the eigenvalues are.
//
// A motion x (dim model.n_dofs: dc, dtheta per free body, global axes) changes the deformation
// coordinates of an element by the linearized kinematics of core/model/element_kinematics.hpp,
//   d xi  = E1^T (dc2 - dc1 - R2 x dtheta2 + (p2 - c1) x dtheta1),
//   d phi = T E1^T (dtheta2 - dtheta1).
// Only the coordinates that carry stiffness count: all six for a beam; for a rail not its axial
// coordinate (the carriage slides), and for a cylindrical rail not its twist either.
//
// Joints (core/model/joint.hpp) are elements too: their gap d g = dc2 - R2 x dtheta2 - dc1 +
// R1 x dtheta1 (R the levers of the joint points) counts for every type, their relative rotation
// dtheta2 - dtheta1 across the axis for a revolute joint, all of it for a fixed joint, none of it
// for a spherical one. A joint is a penalty: the motion of a mechanism it holds (a pendulum's
// swing) strains it by about its relative compliance c (the penalty gives way under the forces
// that carry the swing), while a mode of the joint itself strains it by about its whole motion.
// So a joint counts as deformed only beyond sqrt(c) of the motion (halfway between, in decades):
// its deformation enters weighted by kRigidModeDeformation / sqrt(c) (at most 1).
//
// ratio(x) = max over elements of (|d xi| / L + |d phi|) divided by max over bodies of
// (|dc| / L + |dtheta|), with L the extent of the scene (the largest distance between element
// points and body centres). A rigid motion gives 0 (to rounding); the lowest elastic mode of a
// chain of N equal segments gives about 1/N; so a mode is rigid below kRigidModeDeformation.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// A mode whose element deformation is below this fraction of its motion deforms no element. The
// scene limit of 100,000 segments keeps every elastic mode above ~1e-5; rigid modes computed to the
// eigensolvers' tolerance sit below ~1e-10.
inline constexpr double kRigidModeDeformation = 1e-7;

class ElementDeformation {
 public:
  // Linearizes about the configuration in data.pose.
  ElementDeformation(const Model& model, const Data& data);

  // Relative deformation of the motion x (dim model.n_dofs); 0 for x = 0: of the beams, rails
  // and (weighted) joints.
  double ratio(const Eigen::VectorXd& x) const { return worst(x, true); }
  // The same of the beams and rails alone: a mode that deforms joints and no beam or rail is
  // carried by the joints' penalty stiffness.
  double element_ratio(const Eigen::VectorXd& x) const { return worst(x, false); }

  double length_scale() const { return length_; }

 private:
  struct Row {
    int k1 = -1, k2 = -1;            // free-body indices of the ends, -1 when fixed
    Eigen::Matrix<double, 6, 12> j;  // d (xi, phi) / d (dc1, dtheta1, dc2, dtheta2)
    std::array<bool, 6> counts{};    // coordinates that carry stiffness
    bool joint = false;
    double weight = 1.0;  // a joint's kRigidModeDeformation / sqrt(c), at most 1
  };
  double worst(const Eigen::VectorXd& x, bool joints) const;
  std::vector<Row> rows_;
  double length_ = 1.0;
};

}  // namespace beamrail
