// Element end forces for result tables and stress: the force and moment acting ON an element at
// each end (the finite-element end-force convention, the paper's P1 and P2), in the element frame
// carried by the left end, moments about the attachment points. A beam in tension has fx > 0 at
// end 2 and fx < 0 at end 1.
#pragma once

#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

struct EndForces {
  Vec6 end1 = Vec6::Zero();  // (fx, fy, fz, mx, my, mz) at point 1 [N, N m]
  Vec6 end2 = Vec6::Zero();  // at point 2
};

// End forces of beam `index` / rail `index` in the configuration of data.pose.
EndForces beam_end_forces(const Model& model, const Data& data, int index);
EndForces rail_end_forces(const Model& model, const Data& data, int index);

// Largest |N|/S + |My|/Wy + |Mz|/Wz over both ends [Pa]; NaN when a section modulus is unknown.
double end_stress(const SectionProperties& section, const EndForces& forces);

}  // namespace beamrail
