#include "optimizer/responses.hpp"

#include <cmath>
#include <limits>

#include "core/model/element_forces.hpp"
#include "core/model/rotation.hpp"

namespace beamrail {

double structural_mass(const Model& model) {
  double m = 0.0;
  for (const Body& b : model.bodies) m += b.declared_mass;
  for (const Beam& e : model.beams) m += e.density * e.section.area * e.ends.length;
  for (const Rail& e : model.rails) m += e.density * e.section.area * e.ends.length;
  return m;
}

double mass_response(const Model& model, const ResponseSpec& spec) {
  if (!spec.subset) return structural_mass(model);
  double m = 0.0;
  for (int i : spec.mass_bodies) m += model.bodies[i].declared_mass;
  for (int i : spec.mass_beams) {
    const Beam& e = model.beams[i];
    m += e.density * e.section.area * e.ends.length;
  }
  for (int i : spec.mass_rails) {
    const Rail& e = model.rails[i];
    m += e.density * e.section.area * e.ends.length;
  }
  return m;
}

PointTracker::PointTracker(const Model& model, const ResponseSpec& spec)
    : body_(spec.body), direction_(spec.direction) {
  const Body& b = model.bodies[spec.body];
  initial_lever_ = spec.point - b.position;
  offset_ = rotation_matrix<double>(b.orientation).transpose() * initial_lever_;
}

double PointTracker::value(const Data& data) const {
  const Pose<double>& p = data.pose[body_];
  return (p.u + (p.A * offset_ - initial_lever_)).dot(direction_);
}

void static_responses(const Study& study, int analysis, const Model& model, const Data& data,
                      std::vector<double>& values) {
  for (size_t k = 0; k < study.responses.size(); ++k) {
    const ResponseSpec& r = study.responses[k];
    if (r.analysis != analysis) continue;
    switch (r.quantity) {
      case ResponseSpec::Quantity::kDisplacement:
        values[k] = PointTracker(model, r).value(data);
        break;
      case ResponseSpec::Quantity::kRotation: {
        values[k] = data.rotation[r.body].dot(r.direction);
        break;
      }
      case ResponseSpec::Quantity::kElementForce: {
        const EndForces f = r.element.rail ? rail_end_forces(model, data, r.element.index)
                                           : beam_end_forces(model, data, r.element.index);
        values[k] = (r.element.end == 1 ? f.end1 : f.end2)(r.component);
        break;
      }
      case ResponseSpec::Quantity::kMaxStress: {
        double worst = 0.0;
        for (int i : r.beams)
          worst =
              std::max(worst, end_stress(model.beams[i].section, beam_end_forces(model, data, i)));
        values[k] = worst;
        break;
      }
      default:
        break;
    }
  }
}

void modal_responses(const Study& study, int analysis, const ModalResult& result,
                     std::vector<double>& values) {
  for (size_t k = 0; k < study.responses.size(); ++k) {
    const ResponseSpec& r = study.responses[k];
    if (r.analysis != analysis || r.quantity != ResponseSpec::Quantity::kFrequency) continue;
    const Mode* mode = elastic_mode(result, r.mode);
    values[k] = mode ? mode->frequency_hz : std::numeric_limits<double>::quiet_NaN();
  }
}

void buckling_responses(const Study& study, int analysis, const BucklingResult& result,
                        std::vector<double>& values) {
  for (size_t k = 0; k < study.responses.size(); ++k) {
    const ResponseSpec& r = study.responses[k];
    if (r.analysis != analysis || r.quantity != ResponseSpec::Quantity::kBucklingFactor) continue;
    values[k] = buckling_factor(result, r.mode);
  }
}

}  // namespace beamrail
