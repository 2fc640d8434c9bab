// Assembly of the generalized forces on all bodies and of their exact tangent (stiffness and
// damping blocks) from the element kernels, the loads and gravity.
#pragma once

#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// Sets data.wrench (every body; global force and moment about the centre of mass),
// data.elastic_energy, data.rail_floored and data.out_of_range at time t [s] from data.pose.
// Gravity and loads are scaled by load_factor (static load stepping); t = +infinity gives every
// load its final value.
void compute_wrenches(const Model& model, Data& data, double t, double load_factor = 1.0);

// Sets data.stiffness (and data.damping when with_velocity) for every block of model.pattern at
// time t from data.pose; the velocity blocks are exact for any scene, zero without damping.
// Without with_velocity the bodies are taken at rest (static and modal analyses): damping forces
// and their derivatives vanish there.
void compute_tangent(const Model& model, Data& data, double t, bool with_velocity,
                     double load_factor = 1.0);

// Adds gravity and the loads at time t, scaled by load_factor, to data.wrench (part of
// compute_wrenches).
void add_load_wrenches(const Model& model, Data& data, double t, double load_factor);

// Adds the loads' part of the tangent, scaled by load_factor, to data.stiffness (part of
// compute_tangent): a force of fixed direction at a body point turns its lever with the body,
// d(R x F)/dtheta = [F]x [R]x; a follower load turns with the body as a whole, dF/dtheta =
// -[F]x and d(R x F)/dtheta = -[R x F]x for a force, dM/dtheta = -[M]x for a torque (not
// symmetric). Gravity acts at the centres and adds none.
void add_load_stiffness(const Model& model, Data& data, double t, double load_factor);

// Whether the load has a potential: a force of fixed direction. A torque of fixed direction and a
// follower load have none (their work depends on the path) and make the tangent non-symmetric.
bool is_conservative(const Load& load);

// Whether the motion keeps its energy (kinetic + elastic + gravity): no loads, no driven bodies,
// and every beam and rail undamped and under the energy law (docs/model.md "Two force laws": the
// paper's end wrenches are not a gradient). Joints are penalty elements with a strain energy.
bool conserves_energy(const Model& model);

// Kinetic energy of all free bodies [J].
double kinetic_energy(const Model& model, const Data& data);

// Potential energy of gravity, -sum m g . c over free bodies [J].
double gravity_energy(const Model& model, const Data& data);

// True when any element has damping.
bool has_damping(const Model& model);

}  // namespace beamrail
