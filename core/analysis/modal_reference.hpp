// The configuration the modal integrator linearizes about (core/analysis/modal_integrator.hpp):
// the static equilibrium under the loads at t = 0, at rest ("about": "static", the default when
// one exists within the method's rotation limit), or the initial state ("initial").
#pragma once

#include <string>
#include <vector>

#include "core/analysis/ode_system.hpp"
#include "core/analysis/transient.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// Why the modal integrator linearized about the initial state though "about" did not ask for it.
struct InitialLinearization {
  std::string because;          // "" when it did not
  bool no_equilibrium = false;  // the loads push a free body or mechanism along a direction
                                // without stiffness (a carriage driven along its rail): no
                                // equilibrium exists, and the initial state is the one to take
};

// The state linearized about (options.about), written over `reference` (which holds the initial
// state). False (with *error) when "static" was asked for and no equilibrium was found, or the
// time budget ran out. Without "about", an equilibrium that cannot serve keeps the initial state,
// says why in *initial and adds a warning.
bool modal_reference(const Model& model, const IntegratorOptions& options, OdeContext& context,
                     std::vector<double>& reference, std::vector<std::string>& warnings,
                     InitialLinearization* initial, std::string* error);

// The modal method's rotation limit as messages give it ("1 rad").
std::string rotation_limit_text();

}  // namespace beamrail
