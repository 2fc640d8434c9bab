#include "optimizer/run/responses.hpp"

#include <cmath>
#include <cstdio>
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

namespace {

ShapeByBody shape_by_body(const Model& model, const Eigen::VectorXd& shape) {
  ShapeByBody out;
  for (int k = 0; k < model.n_free(); ++k)
    out[model.bodies[model.free_bodies[k]].name] = shape.segment<6>(kDofsPerBody * k);
  return out;
}

// The reference shape in this model's layout (bodies it lacks stay 0).
Eigen::VectorXd in_layout(const Model& model, const ShapeByBody& shape) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(model.n_dofs);
  for (int k = 0; k < model.n_free(); ++k) {
    const auto it = shape.find(model.bodies[model.free_bodies[k]].name);
    if (it != shape.end()) x.segment<6>(kDofsPerBody * k) = it->second;
  }
  return x;
}

}  // namespace

void modal_responses(const Study& study, int analysis, const Model& model,
                     const ModalResult& result, const ModeShapes* references,
                     std::vector<double>& values, std::vector<std::string>& warnings,
                     ModeShapes* selected, std::vector<int>* chosen) {
  if (chosen) chosen->assign(study.responses.size(), -1);
  for (size_t k = 0; k < study.responses.size(); ++k) {
    const ResponseSpec& r = study.responses[k];
    if (r.analysis != analysis || r.quantity != ResponseSpec::Quantity::kFrequency) continue;
    const Mode* mode = nullptr;
    if (r.dominant >= 0) {
      for (const Mode& m : result.modes)
        if (m.kind != Mode::Kind::kRigid && dominant_direction(m, result) == r.dominant) {
          mode = &m;
          break;
        }
      if (!mode)
        warnings.push_back("frequency response \"" + r.name + "\": none of the " +
                           std::to_string(result.modes.size() - result.rigid_modes) +
                           " elastic modes computed has its dominant direction " +
                           kDirectionNames[r.dominant] + ": compute more modes");
    } else if (r.track && references && references->count(static_cast<int>(k)) &&
               result.mass.rows() == model.n_dofs) {
      const Eigen::VectorXd reference = in_layout(model, references->at(static_cast<int>(k)));
      double best = -1.0;
      for (const Mode& m : result.modes) {
        if (m.kind == Mode::Kind::kRigid) continue;
        const double mac = modal_assurance(reference, m.shape, result.mass);
        if (mac > best) best = mac, mode = &m;
      }
      if (mode && best < kTrackedModeMac) {
        char text[64];
        std::snprintf(text, sizeof text, "%.3f", best);
        warnings.push_back("frequency response \"" + r.name + "\" tracks mode " +
                           std::to_string(r.mode) +
                           " of the study's design, but no computed mode resembles it (best MAC " +
                           text + "): its shape has changed character");
      }
    } else {
      mode = elastic_mode(result, r.mode);
    }
    values[k] = mode ? mode->frequency_hz : std::numeric_limits<double>::quiet_NaN();
    if (chosen && mode) (*chosen)[k] = static_cast<int>(mode - result.modes.data());
    if (r.track && selected && mode)
      (*selected)[static_cast<int>(k)] = shape_by_body(model, mode->shape);
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
