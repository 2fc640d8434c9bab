// Computing the study's named responses from analysis results.
#pragma once

#include <vector>

#include "core/analysis/modal_analysis.hpp"
#include "core/model/data.hpp"
#include "optimizer/study.hpp"

namespace beamrail {

// Total structural mass: declared body masses plus rho S l of every beam and rail with a density.
double structural_mass(const Model& model);

// A mass response: the structural mass, or that of its subset of bodies and elements.
double mass_response(const Model& model, const ResponseSpec& spec);

// Displacement along a direction of a body point, from the initial configuration.
class PointTracker {
 public:
  PointTracker(const Model& model, const ResponseSpec& spec);
  double value(const Data& data) const;

 private:
  int body_;
  Vec3 offset_;         // body axes
  Vec3 initial_lever_;  // point - centre in the initial configuration, global
  Vec3 direction_;
};

// Fills the static responses (displacement, rotation, element_force, max_stress) of analysis
// `analysis` (an index into study.analyses) from the equilibrium in data; others are left alone.
void static_responses(const Study& study, int analysis, const Model& model, const Data& data,
                      std::vector<double>& values);

// Fills the frequency responses of modal analysis `analysis`.
void modal_responses(const Study& study, int analysis, const ModalResult& result,
                     std::vector<double>& values);

// Fills the buckling_factor responses of buckling analysis `analysis` (+infinity for a mode the
// loads do not buckle).
void buckling_responses(const Study& study, int analysis, const BucklingResult& result,
                        std::vector<double>& values);

}  // namespace beamrail
