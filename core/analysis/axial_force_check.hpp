// What the beam law leaves out of an element's axial force (docs/model.md "Axial force and
// bending"): the force acts along the frame the element's left end carries, not along its chord,
// so in that frame an element has no stress stiffness of its own. The real force adds, per element
// and bending plane, the consistent geometric stiffness of a cubic bending shape on the right
// end's offset v and turn t in that frame (where the left end has neither):
// N / (30 l) [36, -3 l; -3 l, 4 l^2], N the axial force (tension positive); in the x-y plane
// v = xi_y, t = phi_z, in the x-z plane v = xi_z, t = -phi_y. Its effect on a result is measured,
// not guessed from the element alone:
//  - a static equilibrium: the correction e of the displacements that the missing forces g make,
//    S e + g(q + e) = 0 (S the tangent of the wrenches; g linear in e), by a fixed-point iteration
//    on the static analysis's factorization, e = -S^-1 (g0 + G e); and whether the structure with
//    the missing stiffness K_s = -G would be unstable (the lowest eigenvalue of K^-1 K_s at or
//    below -1, K = -S), which a perfect column, with no offset to correct, shows only so;
//  - a mode (M-normalized shape x, w^2): w'^2 = w^2 + x^T K_s x (Rayleigh);
//  - a buckling factor (K0 x = lambda (-K1) x): the same quotient with the missing stiffness of
//    the reference state and of the scaled loads per unit factor.
// Segments reduce each as 1/n^2.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// The relative error of a result above which the analysis warns.
inline constexpr double kAxialForceWarning = 0.01;
// A static correction counts relative to its body's displacement along it, but at least this part
// of the largest displacement of any body: a body that barely moves that way (the middle of a
// strut loaded through its ends, 1e-5 of the frame's motion) is no result to warn of.
inline constexpr double kAxialForceFloor = 0.01;

// The missing forces of every beam element at the state in data.pose.
class MissingAxialForces {
 public:
  MissingAxialForces(const Model& model, const Data& data);
  // With the axial forces that the generalized displacement `direction` (n_dofs) adds to the
  // state's, to first order (N = EA d xi_x / l): per unit of a buckling analysis's load factor.
  MissingAxialForces(const Model& model, const Data& data, const Eigen::VectorXd& direction);

  // Whether any element carries an axial force, and whether one is compressed.
  bool any() const { return loaded_ > 0; }
  bool compressed() const;

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
  // Per scene beam: d^T K_b d summed over its elements, d the bending offsets and turns of the
  // elements' right ends in their left ends' frames (xi_y, xi_z, phi_y, phi_z) at the state
  // (v: nullptr) or their change for the generalized displacement *v, K_b the law's bending
  // blocks (core/model/stiffness.hpp).
  std::vector<double> bending_energy(const Eigen::VectorXd* v) const;
  // The largest d^T K_s d / d^T K_b d of any element and deformation d (the largest eigenvalue
  // of K_b^-1 K_s per plane, 0.402 |N| l^2 / EI). What the missing stiffness does to a result
  // also passes through the structure's flexibility (large near buckling), so this bounds an
  // element, not an effect.
  double element_ratio_bound() const;
  // Per scene beam: the axial force of largest magnitude among its elements [N] (tension > 0).
  const std::vector<double>& beam_forces() const { return forces_; }

 private:
  struct Element {
    int free1 = -1, free2 = -1;  // free indices of the two bodies (-1: fixed)
    int beam = 0;                // the scene beam (names_)
    Mat3 e1;                     // the left end's frame, global
    Mat3 t;                      // d phi / d (small rotation of the right end in that frame)
    Vec3 r2;                     // p2 - c2, global
    Vec3 lever1;                 // p2 - c1, global
    Vec3 offset;                 // xi: point 2 in the left end's frame
    Vec3 turn;                   // phi: the right end's rotation measure in that frame
    double n = 0.0, l = 0.0;     // axial force [N], length [m]
    double ea = 0.0, gj = 0.0, eiy = 0.0, eiz = 0.0;  // the beam's rigidities
  };
  // The elements at the state, their axial forces from the state (direction: nullptr) or from
  // the first-order change along *direction.
  void build(const Model& model, const Data& data, const Eigen::VectorXd* direction);
  // d xi and d phi of the element for the generalized displacement v.
  void change(const Element& e, const Eigen::VectorXd& v, Vec3* dxi, Vec3* dphi) const;
  // The missing forces f (conjugate to xi) and m (to phi) of offsets xi (y, z) and turns phi.
  static void local_forces(const Element& e, const Vec3& xi, const Vec3& phi, Vec3* f, Vec3* m);
  // Adds the generalized forces of (f, m) to out.
  void add(const Element& e, const Vec3& f, const Vec3& m, Eigen::VectorXd& out) const;

  Eigen::Index n_ = 0;
  std::vector<Element> elements_;
  std::vector<std::string> names_;
  std::vector<int> counts_;
  std::vector<double> forces_;
  int loaded_ = 0;  // elements with an axial force
};

// What the missing forces do to a static equilibrium; `solve` applies S^-1 (the factorized
// tangent of the wrenches at the state).
struct AxialForceEffect {
  // Per free body, its correction over its displacement along the correction (at least
  // kAxialForceFloor of the largest displacement of any body); the largest. Infinite when the
  // fixed-point iteration diverges.
  double relative = 0.0;
  bool unstable = false;  // the structure with the missing stiffness would be unstable
  int beam = -1;          // the scene beam whose missing stiffness it works against most
};
AxialForceEffect static_axial_force_effect(
    const Model& model, const Data& data, const MissingAxialForces& missing,
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& solve);

// What the missing forces do to a state that is not an equilibrium (a transient's: moving,
// deformed by loads and inertia), the response to them taken as quasi-static: the same
// correction e as static_axial_force_effect's (S the tangent at the state), measured on the
// elements rather than on the displacements (which hold the motion, and whose momentary values
// need not follow the deformation: per body, the static measure gave 1.56 on
// studies/frame_3d.json's transient where a body passed near its start): per scene beam, the
// bending offsets and turns e changes over the state's own,
// sqrt(e^T K_b e / d^T K_b d) (bending_energy), over the beams bent with at least
// kAxialForceFloor^2 of the most bent one's energy; the largest, and that beam. Where the
// fixed-point iteration diverges, of the first-order e = -S^-1 g0. `unstable` is not measured.
AxialForceEffect deformation_axial_force_effect(
    const MissingAxialForces& missing,
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& solve);

// The warning for a transient's state at time t [s], "" below kAxialForceWarning.
std::string transient_axial_force_warning(const MissingAxialForces& missing,
                                          const AxialForceEffect& effect, double t);

// The warning for a static equilibrium, "" when the effect is below kAxialForceWarning.
std::string static_axial_force_warning(const MissingAxialForces& missing,
                                       const AxialForceEffect& effect);

// The warning for buckling factors (shapes x, factors lambda of K0 x = lambda (-K1) x, and
// x^T K0 x): lambda' = (x^T K0 x + x^T Ks0 x) / (x^T K0 x / lambda - x^T Ks1 x), the factor it
// changes most; "" below kAxialForceWarning.
std::string buckling_axial_force_warning(const MissingAxialForces& reference,
                                         const MissingAxialForces& per_factor,
                                         const std::vector<Eigen::VectorXd>& shapes,
                                         const std::vector<double>& factors,
                                         const std::vector<double>& stiffness);

// The warning for the modes (M-normalized shapes, eigenvalues w^2; others skipped: eigenvalue
// <= 0): the mode whose frequency the missing stiffness changes most; "" below
// kAxialForceWarning.
std::string modal_axial_force_warning(const MissingAxialForces& missing,
                                      const std::vector<Eigen::VectorXd>& shapes,
                                      const std::vector<double>& eigenvalues);

}  // namespace beamrail
