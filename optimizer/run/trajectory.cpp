#include "optimizer/run/trajectory.hpp"

#include <cmath>
#include <limits>

#include "core/model/rotation.hpp"

namespace beamrail {

Trajectory trajectory_of(const Model& model) {
  Trajectory t;
  for (int i : model.free_bodies)
    if (!model.bodies[i].generated) t.bodies.push_back(i);
  return t;
}

void Trajectory::record(const TransientSample& sample, const Data& data) {
  times.push_back(sample.t);
  for (int i : bodies) {
    positions.push_back(data.pose[i].u);
    orientations.push_back(data.q[i]);
  }
}

double trajectory_error(const Trajectory& run, const Trajectory& reference) {
  const size_t nb = reference.bodies.size();
  const size_t samples = std::min(run.times.size(), reference.times.size());
  if (samples == 0 || nb == 0 || run.bodies.size() != nb)
    return std::numeric_limits<double>::quiet_NaN();
  double error = 0.0, motion = 0.0;
  for (size_t k = 0; k < reference.times.size(); ++k)
    for (size_t b = 0; b < nb; ++b)
      motion = std::max(motion, (reference.positions[k * nb + b] - reference.positions[b]).norm());
  for (size_t k = 0; k < samples; ++k)
    for (size_t b = 0; b < nb; ++b)
      error = std::max(error, (run.positions[k * nb + b] - reference.positions[k * nb + b]).norm());
  if (!(motion > kLeastMotion)) return std::numeric_limits<double>::quiet_NaN();
  return error / motion;
}

double trajectory_rotation_error(const Trajectory& run, const Trajectory& reference) {
  const size_t nb = reference.bodies.size();
  const size_t samples = std::min(run.times.size(), reference.times.size());
  if (samples == 0 || nb == 0 || run.bodies.size() != nb ||
      run.orientations.size() != run.positions.size() ||
      reference.orientations.size() != reference.positions.size())
    return std::numeric_limits<double>::quiet_NaN();
  // The angle of the rotation from a to b (Euler parameters, either sign, any norm).
  const auto angle = [](const Vec4& a, const Vec4& b) {
    const Vec4 r = quat_multiply(Vec4(a(0), -a(1), -a(2), -a(3)), b);
    return 2.0 * std::atan2(r.tail<3>().norm(), std::abs(r(0)));
  };
  const std::vector<Vec4>& r = reference.orientations;
  double error = 0.0, motion = 0.0;
  bool finite = true;
  for (size_t k = 0; k < reference.times.size(); ++k)
    for (size_t b = 0; b < nb; ++b) {
      const double a = angle(r[b], r[k * nb + b]);
      finite = finite && std::isfinite(a);
      motion = std::max(motion, a);
    }
  for (size_t k = 0; k < samples; ++k)
    for (size_t b = 0; b < nb; ++b) {
      const double a = angle(run.orientations[k * nb + b], r[k * nb + b]);
      finite = finite && std::isfinite(a);
      error = std::max(error, a);
    }
  if (!finite || !(motion > kLeastTurn)) return std::numeric_limits<double>::quiet_NaN();
  return error / motion;
}

}  // namespace beamrail
