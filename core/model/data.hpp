// Data: everything mutable for one evaluation of a Model. One Data per thread; nothing in it is
// shared, and nothing is allocated after construction on the evaluation path.
#pragma once

#include <vector>

#include "core/model/element_kinematics.hpp"
#include "core/model/model.hpp"

namespace beamrail {

struct Data {
  explicit Data(const Model& model);

  std::vector<Pose<double>> pose;  // per body (fixed bodies hold their initial pose)
  std::vector<Vec4> q;             // Euler parameters per body
  std::vector<Vec3> w;             // angular velocity in body axes per body [rad/s]
  // Rotation vector of each body from its initial orientation, global axes [rad], followed
  // continuously through pi (a body twisted by 7 rad reports 7 rad, not 7 - 2 pi). Kept by
  // apply_increment and reset_to_initial (static analysis); other analyses leave it alone.
  std::vector<Vec3> rotation;

  std::vector<Vec6> wrench;        // per body: force and moment about the centre, global [N, N m]
  double elastic_energy = 0.0;     // sum of element strain energies [J]
  std::vector<char> rail_floored;  // per rail: |l| was at min_length in the last evaluation
  std::vector<char> rail_floored_ever;  // per rail: ... in any evaluation so far
  // An element outside the range of its law (beam_out_of_range, rail_out_of_range) in the last
  // evaluation of the wrenches.
  bool out_of_range = false;

  // Tangent blocks, one per model.pattern block (row body, column body):
  std::vector<Mat6> stiffness;  // d wrench_row / d (dc, dtheta)_col  [N/m, N, N m]
  std::vector<Mat6> damping;    // d wrench_row / d (v, omega)_col    [N s/m, N m s]

  long n_wrench_evaluations = 0;
  long n_tangent_evaluations = 0;
};

// The centre of mass of body i in global coordinates [m]: its reference position plus pose[i].u.
inline Vec3 centre(const Model& model, const Data& data, int i) {
  return model.bodies[i].position + data.pose[i].u;
}

// Sets pose, q and w of the free bodies from a state vector y (dim model.n_states; its centres
// are displacements u from the bodies' initial positions, core/model/dynamics.hpp).
void set_state(const Model& model, Data& data, const double* y);

// Sets pose, q and w of the driven bodies (model.driven_bodies) at time t [s] from their
// prescribed motion (core/model/motion.hpp). Every analysis of motion calls it with set_state.
void set_driven_poses(const Model& model, Data& data, double t);

// Writes the initial state of the free bodies into y (dim model.n_states).
void initial_state(const Model& model, double* y);

// The initial state with the centres and orientations of `configuration` (a static equilibrium,
// say) and the scene's initial velocities, into y (dim model.n_states).
void initial_state_at(const Model& model, const Data& configuration, double* y);

}  // namespace beamrail
