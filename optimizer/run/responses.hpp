// Computing the study's named responses from analysis results.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/sensitivity.hpp"
#include "core/model/data.hpp"
#include "core/model/element_forces.hpp"
#include "core/model/element_kinds.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {

// Total structural mass: declared body masses plus the elements' (rho S l of every beam and rail
// with a density; joints have none).
// On the model's scalar (double, or HyperDual for the design sensitivities).
template <class S>
S structural_mass(const ModelT<S>& model) {
  S m = 0.0;
  for (const BodyT<S>& b : model.bodies) m += b.declared_mass;
  for_each_element(model, [&m](auto kind, const auto& e, int) { m += decltype(kind)::mass(e); });
  return m;
}

// A mass response: the structural mass, or that of its subset of bodies and elements.
template <class S>
S mass_response(const ModelT<S>& model, const ResponseSpec& spec) {
  if (!spec.subset) return structural_mass(model);
  S m = 0.0;
  for (int i : spec.mass_bodies) m += model.bodies[i].declared_mass;
  for (int i : spec.mass_beams) {
    const BeamT<S>& e = model.beams[i];
    m += e.density * e.section.area * e.ends.length;
  }
  for (int i : spec.mass_rails) {
    const RailT<S>& e = model.rails[i];
    m += e.density * e.section.area * e.ends.length;
  }
  return m;
}

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
  // With spec.relative_to: the reference body, its initial orientation, and the point's initial
  // position from its centre (global).
  int frame_ = -1;
  Mat3 frame_orientation_ = Mat3::Identity();
  Vec3 initial_in_frame_ = Vec3::Zero();
};

// Fills the static responses (displacement, rotation, element_force, max_stress) of analysis
// `analysis` (an index into study.analyses) from the equilibrium in data; others are left alone.
void static_responses(const Study& study, int analysis, const Model& model, const Data& data,
                      std::vector<double>& values);

// The total derivatives along a design direction of the static responses of `analysis`, written
// where static_responses writes their values: the responses on hyper-dual numbers over
// `direction` at the equilibrium `data` (of `base`) moved by e2 v (v = du/dp), their e2 parts.
// Where a response is not smooth (a max_stress whose force is zero or whose largest ends tie, a
// joint_gap of a joint carrying nothing) its derivative is the one as the variables grow, and a
// warning says so (into `warnings`).
void static_response_derivatives(const Study& study, int analysis, const Model& base,
                                 const Data& data, const DualModel& direction,
                                 const Eigen::VectorXd& v, std::vector<double>& values,
                                 std::vector<std::string>* warnings);

// Relative to the largest stress: a stress term |N|/S, |My|/Wy or |Mz|/Wz below this is a zero
// force (rounding leaves ~1e-16: a planar frame's out-of-plane moment), and ends within it of the
// largest tie. Relative to the derivative: a kink's share that counts.
inline constexpr double kStressKink = 1e-9;

// The derivative, as the variables grow, of max_stress over the beams' end forces `forces` (on
// hyper-dual numbers: e2 along the design) with `sections`: |f| at f = 0 grows as |df|, and of
// tied ends the largest derivative wins. *kink when either changed it (the derivative the other
// way differs). NaN when a section modulus is unknown. An adversarial review (2026-12-01) found
// a column turned about its axis by p (its section's axes) with dstress/dp -5.06e7 Pa/m where
// the stress is V-shaped about p = 0 and grows by 5.06e7 Pa/m either way: |Mz| was -1e-16.
double max_stress_derivative(const std::vector<const SectionPropertiesT<HyperDual>*>& sections,
                             const std::vector<EndForcesT<HyperDual>>& forces, bool* kink);

// A mode shape by body name (dc, dtheta of each free body): comparable between designs whose
// bodies are numbered differently.
using ShapeByBody = std::map<std::string, Vec6>;
// Per frequency response (index into study.responses), the shape of the mode it reads.
using ModeShapes = std::map<int, ShapeByBody>;

// Fills the frequency responses of modal analysis `analysis` (of `model`): by mode number, by
// dominant direction, or, for a tracked response with a reference shape in `references`, the mode
// whose shape has the largest MAC against it. Warns (into `warnings`) of a dominant direction no
// computed mode has and of a tracked mode that resembles its reference poorly (MAC below
// kTrackedModeMac). The shapes of the modes tracked responses read go to `selected` (when given);
// `chosen` (when given) receives per study response the index in result.modes of the mode it read,
// or -1.
void modal_responses(const Study& study, int analysis, const Model& model,
                     const ModalResult& result, const ModeShapes* references,
                     std::vector<double>& values, std::vector<std::string>& warnings,
                     ModeShapes* selected, std::vector<int>* chosen = nullptr);

// Below this MAC against its reference a tracked mode is reported with a warning.
inline constexpr double kTrackedModeMac = 0.5;

// Fills the buckling_factor responses of buckling analysis `analysis` (+infinity for a mode the
// loads do not buckle).
void buckling_responses(const Study& study, int analysis, const BucklingResult& result,
                        std::vector<double>& values);

}  // namespace beamrail
