#include "optimizer/run/responses.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "core/model/element_forces.hpp"
#include "core/model/element_kinds.hpp"
#include "core/model/joint_forces.hpp"
#include "core/model/rotation.hpp"

namespace beamrail {

PointTracker::PointTracker(const Model& model, const ResponseSpec& spec)
    : body_(spec.body), direction_(spec.direction) {
  const Body& b = model.bodies[spec.body];
  initial_lever_ = spec.point - b.position;
  offset_ = rotation_matrix<double>(b.orientation).transpose() * initial_lever_;
  if (spec.relative_to >= 0) {
    const Body& f = model.bodies[spec.relative_to];
    frame_ = spec.relative_to;
    frame_orientation_ = rotation_matrix<double>(f.orientation);
    initial_in_frame_ = spec.point - f.position;
  }
}

namespace {

// The displacement along `direction` of the point at `lever` (global, from the centre) in the
// initial configuration, `offset` in body axes, of a body at pose p.
template <class S>
S point_displacement(const Pose<S>& p, const Vec3T<S>& offset, const Vec3T<S>& lever,
                     const Vec3& direction) {
  return (p.u + (p.A * offset - lever)).dot(direction.cast<S>());
}

}  // namespace

double PointTracker::value(const Data& data) const {
  if (frame_ < 0) return point_displacement(data.pose[body_], offset_, initial_lever_, direction_);
  // The point's position from the reference body's centre, turned back by the body's rotation
  // since the start (A0 A^T): its displacement as an observer riding on that body sees it.
  const Pose<double>& p = data.pose[body_];
  const Pose<double>& f = data.pose[frame_];
  const Vec3 moved = p.u + p.A * offset_ - initial_lever_;  // global displacement of the point
  const Vec3 seen = frame_orientation_ * (f.A.transpose() * (initial_in_frame_ + moved - f.u));
  return (seen - initial_in_frame_).dot(direction_);
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
        const EndForces f =
            visit_element(model, r.element.ref, [&](auto kind, const auto&, int index) {
              return decltype(kind)::end_forces(model, data.pose, index);
            });
        values[k] = (r.element.end == 1 ? f.end1 : f.end2)(r.component);
        break;
      }
      case ResponseSpec::Quantity::kJointGap: {
        const Joint& j = model.joints[r.joint];
        values[k] = joint_gap(j, data.pose[j.body1], data.pose[j.body2]).norm();
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

double max_stress_derivative(const std::vector<const SectionPropertiesT<HyperDual>*>& sections,
                             const std::vector<EndForcesT<HyperDual>>& forces, bool* kink) {
  // The stresses' values first: the largest sets what counts as zero and as a tie.
  const auto term_value = [](const HyperDual& f, const HyperDual& w) {
    return std::abs(f.v) / w.v;
  };
  double worst = 0.0;
  for (size_t i = 0; i < forces.size(); ++i)
    for (const Vec6T<HyperDual>* p : {&forces[i].end1, &forces[i].end2}) {
      const SectionPropertiesT<HyperDual>& s = *sections[i];
      if (!(s.area.v > 0.0) || !(s.wy.v > 0.0) || !(s.wz.v > 0.0))
        return std::numeric_limits<double>::quiet_NaN();
      worst = std::max(worst, term_value((*p)(0), s.area) + term_value((*p)(4), s.wy) +
                                  term_value((*p)(5), s.wz));
    }
  const double zero = kStressKink * worst;
  double best = -std::numeric_limits<double>::infinity(), lowest_tied = best;
  double kinked = 0.0;  // the derivative's part from the terms at their kink
  for (size_t i = 0; i < forces.size(); ++i)
    for (const Vec6T<HyperDual>* p : {&forces[i].end1, &forces[i].end2}) {
      const SectionPropertiesT<HyperDual>& s = *sections[i];
      double value = 0.0, derivative = 0.0;
      for (const auto& [f, w] :
           {std::pair{(*p)(0), s.area}, std::pair{(*p)(4), s.wy}, std::pair{(*p)(5), s.wz}}) {
        value += term_value(f, w);
        if (term_value(f, w) <= zero) {
          // |f| / w at f = 0 (up to rounding): |df| / w as p grows.
          derivative += std::abs(f.b) / w.v;
          kinked = std::max(kinked, std::abs(f.b) / w.v);
        } else {
          derivative += (f.v < 0.0 ? -f.b : f.b) / w.v - std::abs(f.v) * w.b / (w.v * w.v);
        }
      }
      if (value < worst - zero) continue;  // not the largest
      lowest_tied = best == -std::numeric_limits<double>::infinity()
                        ? derivative
                        : std::min(lowest_tied, derivative);
      best = std::max(best, derivative);
    }
  const double scale = std::abs(best);
  *kink = kinked > kStressKink * scale || best - lowest_tied > kStressKink * scale;
  return best;
}

void static_response_derivatives(const Study& study, int analysis, const Model& base,
                                 const Data& data, const DualModel& direction,
                                 const Eigen::VectorXd& v, std::vector<double>& values,
                                 std::vector<std::string>* warnings) {
  using H = HyperDual;
  const std::vector<Pose<H>> pose = dual_poses(base, data, direction, v, Eigen::VectorXd());
  for (size_t k = 0; k < study.responses.size(); ++k) {
    const ResponseSpec& r = study.responses[k];
    if (r.analysis != analysis) continue;
    switch (r.quantity) {
      case ResponseSpec::Quantity::kDisplacement: {
        // Without a point given, the point is the body's centre (which may move with p).
        const BodyT<H>& b = direction.bodies[r.body];
        const Vec3T<H> lever =
            r.point_given ? Vec3T<H>(r.point.cast<H>() - b.position) : Vec3T<H>(Vec3T<H>::Zero());
        const Vec3T<H> offset = rotation_matrix<H>(b.orientation).transpose() * lever;
        values[k] = point_displacement(pose[r.body], offset, lever, r.direction).b;
        break;
      }
      case ResponseSpec::Quantity::kRotation: {
        // The rotation vector from the initial orientation, theta = log(A A0^T): a turn e dtheta
        // of the body changes it by J(theta)^-1 dtheta (rotation_vector_rate); it does not depend
        // on A0 itself.
        const int f = base.bodies[r.body].free_index;
        values[k] = f < 0 || v.size() == 0
                        ? 0.0
                        : rotation_vector_rate(data.rotation[r.body],
                                               Vec3(v.segment<3>(kDofsPerBody * f + 3)))
                              .dot(r.direction);
        break;
      }
      case ResponseSpec::Quantity::kElementForce: {
        const EndForcesT<H> f =
            visit_element(direction, r.element.ref, [&](auto kind, const auto&, int index) {
              return decltype(kind)::end_forces(direction, pose, index);
            });
        values[k] = (r.element.end == 1 ? f.end1 : f.end2)(r.component).b;
        break;
      }
      case ResponseSpec::Quantity::kJointGap: {
        // d|g| = g . dg / |g|; at g = 0 (a joint that carries nothing) |g| has a kink, and its
        // derivative as the variables grow is |dg|.
        const JointT<H>& j = direction.joints[r.joint];
        const Vec3T<H> g = joint_gap(j, pose[j.body1], pose[j.body2]);
        const H squared = g.dot(g);
        Vec3 dg;
        for (int c = 0; c < 3; ++c) dg(c) = g(c).b;
        values[k] = squared.v > 0.0 ? 0.5 * squared.b / std::sqrt(squared.v) : dg.norm();
        if (!(squared.v > 0.0) && dg.norm() > 0.0 && warnings)
          warnings->push_back("joint_gap response \"" + r.name +
                              "\" is at a kink (the joint carries nothing): its derivative is "
                              "the one as the variables grow");
        break;
      }
      case ResponseSpec::Quantity::kMaxStress: {
        std::vector<EndForcesT<H>> forces;
        std::vector<const SectionPropertiesT<H>*> sections;
        for (int i : r.beams) {
          forces.push_back(beam_end_forces(direction, pose, i));
          sections.push_back(&direction.beams[i].section);
        }
        bool kink = false;
        values[k] = max_stress_derivative(sections, forces, &kink);
        if (kink && warnings)
          warnings->push_back(
              "max_stress response \"" + r.name +
              "\" is at a kink (a force of a section that is zero, or two ends equally "
              "stressed): its derivative is the one as the variables grow, and the other way it "
              "differs");
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
