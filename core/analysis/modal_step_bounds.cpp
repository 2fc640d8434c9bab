#include "core/analysis/modal_step_bounds.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>
#include <utility>
#include <vector>

#include "core/analysis/modal_coordinates.hpp"
#include "core/model/element_kinematics.hpp"

namespace beamrail {

double turning_step_bound(double rtol) {
  return std::min(kTurningFrameStep * std::pow(rtol / kTurningFrameRtol, 0.25),
                  kTurningFrameLongestStep);
}

double mechanism_step_bound(double rtol) {
  return std::min(kMechanismStep * std::pow(rtol / kMechanismRtol, 0.25), kMechanismLongestStep);
}

bool moves_as_mechanism(const Model& model) {
  std::vector<char> floating(model.n_free(), 0);
  for (const std::vector<int>& part : floating_parts(model))
    for (int i : part) floating[i] = 1;
  for (int i : free_bodies_not_held(model))
    if (!floating[i]) return true;
  return false;
}

namespace {

// Twice mode i's energy: zdot_i^2 + lambda_i z_i^2 (lambda below 0 taken as 0).
double mode_energy(const Eigen::ArrayXd& lambda, const ModeBlock& z, Eigen::Index i) {
  return z(i, 1) * z(i, 1) + std::max(lambda[i], 0.0) * z(i, 0) * z(i, 0);
}

}  // namespace

double modal_stiff_share(const Eigen::ArrayXd& lambda, const ModeBlock& z) {
  if (lambda.size() == 0) return 0.0;
  const double lambda_stiff = kMechanismStiffModes * kMechanismStiffModes * lambda.maxCoeff();
  double total = 0.0, stiff = 0.0;
  for (Eigen::Index i = 0; i < lambda.size(); ++i) {
    const double e = mode_energy(lambda, z, i);
    total += e;
    if (std::max(lambda[i], 0.0) > lambda_stiff) stiff += e;
  }
  return total > 0.0 ? stiff / total : 0.0;
}

double modal_ringing_rate(const Eigen::ArrayXd& lambda, const std::vector<Eigen::Index>& order,
                          const ModeBlock& z, double share) {
  double total = 0.0;
  for (Eigen::Index i = 0; i < lambda.size(); ++i) total += mode_energy(lambda, z, i);
  if (!(total > 0.0)) return 0.0;
  double above = 0.0;
  for (Eigen::Index i : order) {
    above += mode_energy(lambda, z, i);
    if (above > share * total) return std::sqrt(std::max(lambda[i], 0.0));
  }
  return 0.0;
}

namespace {

// How far the offsets `v` (6 rows per free body) move the element of lever `l`: |d xi| and the
// change of its relative rotation.
std::pair<double, double> lever_motion(const ElementLever& l, const double* v) {
  const auto part = [v](int row, int offset) {
    return row >= 0 ? Vec3(v[row + offset], v[row + offset + 1], v[row + offset + 2])
                    : Vec3::Zero();
  };
  const Vec3 turn1 = part(l.row1, 3), turn2 = part(l.row2, 3);
  const Vec3 p1 = part(l.row1, 0) + turn1.cross(l.arm1);
  const Vec3 p2 = part(l.row2, 0) + turn2.cross(l.arm2);
  const Vec3 turn = turn2 - turn1;
  return {(p2 - p1 - turn1.cross(l.span)).norm(),
          (turn - turn.dot(l.free_axis) * l.free_axis).norm()};
}

}  // namespace

ElementReach element_reach(const Model& model, const Data& data, const Eigen::MatrixXd& phi) {
  ElementReach reach;
  const auto add = [&](const ElementEnds& ends, RotationMeasure measure, bool twist_free) {
    const ElementFrames<double> f =
        element_frames(ends, data.pose[ends.body1], data.pose[ends.body2], measure);
    const auto row = [&model](int body) {
      const int free = model.bodies[body].free_index;
      return free >= 0 ? kDofsPerBody * free : -1;
    };
    reach.levers.push_back({row(ends.body1), row(ends.body2), f.R1, f.R2, f.lever1 - f.R1,
                            twist_free ? Vec3(f.E1.col(0)) : Vec3::Zero()});
  };
  for (const Beam& e : model.beams) add(e.ends, rotation_measure(e), false);
  for (const Rail& e : model.rails)
    add(e.ends, rotation_measure(e), e.type == RailType::kCylindrical);
  const Eigen::Index modes = phi.cols(), elements = static_cast<Eigen::Index>(reach.levers.size());
  reach.length = reach.angle = Eigen::ArrayXXd::Zero(modes, elements);
  reach.largest = Eigen::ArrayX2d::Zero(modes, 2);
  for (Eigen::Index i = 0; i < modes; ++i)
    for (Eigen::Index e = 0; e < elements; ++e)
      std::tie(reach.length(i, e), reach.angle(i, e)) =
          lever_motion(reach.levers[e], phi.col(i).data());
  if (elements > 0) {
    reach.largest.col(0) = reach.length.rowwise().maxCoeff();
    reach.largest.col(1) = reach.angle.rowwise().maxCoeff();
  }
  return reach;
}

void element_motion(const ElementReach& reach, const Eigen::Ref<const Eigen::VectorXd>& v,
                    Eigen::ArrayXd* length, Eigen::ArrayXd* angle) {
  const auto elements = static_cast<Eigen::Index>(reach.levers.size());
  length->resize(elements);
  angle->resize(elements);
  for (Eigen::Index e = 0; e < elements; ++e)
    std::tie((*length)[e], (*angle)[e]) = lever_motion(reach.levers[e], v.data());
}

Eigen::ArrayXd modal_swing(const Eigen::ArrayXd& lambda, const Eigen::ArrayXd& damping,
                           const ModeBlock& z, const Eigen::ArrayXd& psi_a) {
  Eigen::ArrayXd swing = Eigen::ArrayXd::Zero(lambda.size());
  for (Eigen::Index i = 0; i < lambda.size(); ++i) {
    if (!(lambda[i] > 0.0)) continue;
    const double offset = (psi_a[i] + (damping.size() ? damping[i] * z(i, 1) : 0.0)) / lambda[i];
    swing[i] = std::sqrt(offset * offset + z(i, 1) * z(i, 1) / lambda[i]);
  }
  return swing;
}

double modal_edge_rate(const Eigen::ArrayXd& lambda, const std::vector<Eigen::Index>& order,
                       const Eigen::ArrayXd& swing, const Eigen::Ref<const Eigen::ArrayXd>& reach,
                       double margin, double share) {
  double above = 0.0;
  for (Eigen::Index i : order) {
    if (!(lambda[i] > 0.0)) continue;
    above += reach[i] * swing[i];
    if (above > share * margin) return std::sqrt(lambda[i]);
  }
  return 0.0;
}

double modal_elements_edge_rate(const Eigen::ArrayXd& lambda,
                                const std::vector<Eigen::Index>& order, const Eigen::ArrayXd& swing,
                                const ElementReach& reach,
                                const std::vector<double>& length_margins,
                                const std::vector<double>& angle_margins, double share) {
  const double length_swing = (reach.largest.col(0) * swing).sum();
  const double angle_swing = (reach.largest.col(1) * swing).sum();
  double rate = 0.0;
  for (size_t e = 0; e < length_margins.size(); ++e) {
    const auto col = static_cast<Eigen::Index>(e);
    if (length_swing > share * length_margins[e])
      rate = std::max(rate, modal_edge_rate(lambda, order, swing, reach.length.col(col),
                                            length_margins[e], share));
    if (angle_swing > share * angle_margins[e])
      rate = std::max(rate, modal_edge_rate(lambda, order, swing, reach.angle.col(col),
                                            angle_margins[e], share));
  }
  return rate;
}

double modal_slow_edge_step(const Eigen::ArrayXd& lambda, const Eigen::ArrayXd& accel,
                            const Eigen::MatrixXd& phi, const ElementReach& reach,
                            const std::vector<double>& length_margins,
                            const std::vector<double>& angle_margins, double h, double share) {
  const double slow = kResolvedPhase * kResolvedPhase;
  Eigen::VectorXd a = Eigen::VectorXd::Zero(lambda.size());
  bool any = false;
  for (Eigen::Index i = 0; i < lambda.size(); ++i)
    if (!(lambda[i] * h * h > slow) && accel[i] != 0.0) {
      a[i] = accel[i];
      any = true;
    }
  if (!any) return h;
  // Their acceleration together: modes that cancel in an element (two bodies falling together,
  // rigid modes that mix their common motion with their relative one) do not move it.
  const Eigen::VectorXd offsets = phi * a;
  Eigen::ArrayXd length, angle;
  element_motion(reach, offsets, &length, &angle);
  const auto limit = [&](double drift, double margin) {
    if (margin > 0.0 && drift * h * h / 8.0 > share * margin)
      h = std::sqrt(8.0 * share * margin / drift);
  };
  for (size_t e = 0; e < length_margins.size(); ++e) {
    const auto col = static_cast<Eigen::Index>(e);
    limit(length[col], length_margins[e]);
    limit(angle[col], angle_margins[e]);
  }
  return h;
}

ModeBlock ringing_about_static_state(const Eigen::ArrayXd& lambda, const ModeBlock& z,
                                     const Eigen::VectorXd& psi_a) {
  ModeBlock out = z;
  for (Eigen::Index i = 0; i < lambda.size(); ++i)
    if (lambda[i] > 0.0 && std::abs(psi_a[i]) / lambda[i] > std::abs(z(i, 0)))
      out(i, 0) = psi_a[i] / lambda[i];
  return out;
}

ModalStepBounds::ModalStepBounds(double rtol, double w_max, bool turning_frame,
                                 bool mechanism_moves, double harmonic_hz) {
  if (w_max > 0.0) {
    if (turning_frame) turning = turning_step_bound(rtol) / w_max;
    if (mechanism_moves) {
      mechanism_wh = mechanism_step_bound(rtol);
      mechanism = mechanism_wh / w_max;
    }
  }
  if (harmonic_hz > 0.0)
    harmonic = kHarmonicStep * std::pow(rtol, 0.25) / (2.0 * std::numbers::pi * harmonic_hz);
}

double ModalStepBounds::limit(double h, double estimates, bool mechanism_holds,
                              double ringing_rate) const {
  if (turning > 0.0) h = std::min(h, turning);
  if (mechanism_holds)
    h = std::min(h, std::max(mechanism, estimates / kMechanismMostShorter));
  else if (mechanism_wh > 0.0 && ringing_rate > 0.0)
    h = std::min(h, std::max(mechanism_wh / ringing_rate, estimates / kMechanismMostShorter));
  if (harmonic > 0.0) h = std::min(h, harmonic);
  return h;
}

}  // namespace beamrail
