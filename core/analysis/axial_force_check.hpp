// What the beam law leaves out of an element's axial force (docs/model.md "Axial force and
// bending"): the force acts along the frame the element's left end carries, not along its chord,
// so an element has no stress stiffness of its own. The real force along the chord adds, per
// element, a transverse force on its right end of -c N / l times the transverse offset xi_y, xi_z
// of point 2 in that frame (and the opposite on its left end; c = kStringStiffnessFactor, N the
// axial force, tension positive). Its effect on a result is measured, not guessed from the
// element alone:
//  - a static equilibrium: the correction e of the displacements that the missing forces g make,
//    S e + g(q + e) = 0 (S the tangent of the wrenches; g linear in e), by a fixed-point iteration
//    on the static analysis's factorization: e = -S^-1 (g0 + G e);
//  - a mode (M-normalized shape x, w^2): the Rayleigh quotient's change, the relative frequency
//    change 1/2 x^T K_s x / w^2 with K_s = -G the missing stiffness.
// Segments reduce both as 1/n^2 (each element's share of the beam's bending shortens).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// c of -c N / l: the consistent geometric stiffness of a cubic bending shape (6/5 N/l), which
// makes a cantilever's first-order stiffness 3 EI / L^3 (1 -+ 2/5 N L^2 / EI) exact
// (docs/model.md).
inline constexpr double kStringStiffnessFactor = 1.2;
// The relative error of a result above which the analysis warns.
inline constexpr double kAxialForceWarning = 0.01;

// The missing forces of every beam element at the state in data.pose.
class MissingAxialForces {
 public:
  MissingAxialForces(const Model& model, const Data& data);

  // Whether any element carries an axial force.
  bool any() const { return !elements_.empty(); }

  // The wrench vector (n_dofs, generalized forces on the free bodies) of the missing forces at
  // the state, g0.
  Eigen::VectorXd at_state() const;
  // Its linearization G v for a generalized displacement v (n_dofs): the missing forces the
  // offsets v add.
  Eigen::VectorXd of(const Eigen::VectorXd& v) const;
  // v^T K_s v = -v^T G v, per scene beam (in the order of beam_names()).
  std::vector<double> stiffness_energy(const Eigen::VectorXd& v) const;
  // The scene beams (a split beam's segments together) and their element counts.
  const std::vector<std::string>& beam_names() const { return names_; }
  const std::vector<int>& beam_elements() const { return counts_; }
  // Per scene beam: the largest |N| of its elements [N] and its sign (tension > 0).
  const std::vector<double>& beam_forces() const { return forces_; }

 private:
  struct Element {
    int free1 = -1, free2 = -1;  // free indices of the two bodies (-1: fixed)
    int beam = 0;                // the scene beam (names_)
    Mat3 e1;                     // the left end's frame, global
    Vec3 r2;                     // p2 - c2, global
    Vec3 lever1;                 // p2 - c1, global
    Vec3 offset;                 // xi (point 2 in the left end's frame)
    double k = 0.0;              // c N / l
  };
  // d xi of the element for the generalized displacement v.
  Vec3 offset_change(const Element& e, const Eigen::VectorXd& v) const;
  // Adds the wrenches of a force f (global) on point 2 and -f on the left end to out.
  void add(const Element& e, const Vec3& f, Eigen::VectorXd& out) const;

  Eigen::Index n_ = 0;
  std::vector<Element> elements_;
  std::vector<std::string> names_;
  std::vector<int> counts_;
  std::vector<double> forces_;
};

// The relative change of a static equilibrium's displacements that the missing forces make
// (largest translation of the correction over the largest translation from the initial
// configuration), and per scene beam its share; `solve` applies S^-1 (the factorized tangent of
// the wrenches at the state). Infinite when the iteration diverges (the left-out compression
// would buckle the structure) or the state has not moved.
struct AxialForceEffect {
  double relative = 0.0;
  int beam = -1;  // the scene beam whose missing forces do most of it (-1: none)
};
AxialForceEffect static_axial_force_effect(
    const Model& model, const Data& data, const MissingAxialForces& missing,
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& solve);

// The warning for a static equilibrium, "" below kAxialForceWarning.
std::string static_axial_force_warning(const MissingAxialForces& missing,
                                       const AxialForceEffect& effect);

// The warning for the modes (M-normalized shapes, eigenvalues w^2): the mode whose frequency the
// missing stiffness changes most, "" below kAxialForceWarning.
std::string modal_axial_force_warning(const MissingAxialForces& missing,
                                      const std::vector<Eigen::VectorXd>& shapes,
                                      const std::vector<double>& eigenvalues);

}  // namespace beamrail
