#include "optimizer/run/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/model/rotation.hpp"

namespace beamrail {

Trajectory trajectory_of(const Model& model, long rows) {
  Trajectory t;
  for (int i : model.free_bodies)
    if (!model.bodies[i].generated) t.bodies.push_back(i);
  const long per_row = std::max(1L, static_cast<long>(t.bodies.size()));
  if (rows > 0 && rows > kTrajectoryBodySamples / per_row)
    t.stride = (rows * per_row + kTrajectoryBodySamples - 1) / kTrajectoryBodySamples;
  return t;
}

void Trajectory::record(const TransientSample& sample, const Data& data) {
  if (seen++ % stride != 0) return;
  times.push_back(sample.t);
  for (int i : bodies) {
    positions.push_back(data.pose[i].u);
    orientations.push_back(data.q[i]);
  }
}

namespace {

// The largest distance of a value from the same body's first (values: time-major, nb per time);
// NaN when one is not finite.
template <class Value, class Distance>
double largest_from_start(const std::vector<Value>& values, size_t nb, Distance distance) {
  double largest = 0.0;
  for (size_t k = 0; nb > 0 && k < values.size() / nb; ++k)
    for (size_t b = 0; b < nb; ++b) {
      const double d = distance(values[b], values[k * nb + b]);
      if (!std::isfinite(d)) return std::numeric_limits<double>::quiet_NaN();
      largest = std::max(largest, d);
    }
  return largest;
}

double centre_distance(const Vec3& a, const Vec3& b) { return (a - b).norm(); }

// The largest distance between the runs' values of a body over the common samples, relative to
// the largest distance of a reference value from the body's first (values: time-major, one per
// body); NaN when nothing can be compared, a distance is not finite, or the reference moves no
// more than `least`.
template <class Value, class Distance>
double relative_error(const Trajectory& run, const Trajectory& reference,
                      const std::vector<Value>& run_values, const std::vector<Value>& values,
                      Distance distance, double least) {
  const size_t nb = reference.bodies.size();
  const size_t samples = std::min(run.times.size(), reference.times.size());
  if (samples == 0 || nb == 0 || run.bodies.size() != nb ||
      run_values.size() != run.times.size() * nb || values.size() != reference.times.size() * nb)
    return std::numeric_limits<double>::quiet_NaN();
  const double motion = largest_from_start(values, nb, distance);
  bool finite = std::isfinite(motion);
  double error = 0.0;
  for (size_t k = 0; k < samples; ++k)
    for (size_t b = 0; b < nb; ++b) {
      const double d = distance(run_values[k * nb + b], values[k * nb + b]);
      finite = finite && std::isfinite(d);
      error = std::max(error, d);
    }
  if (!finite || !(motion > least)) return std::numeric_limits<double>::quiet_NaN();
  return error / motion;
}

}  // namespace

double trajectory_error(const Trajectory& run, const Trajectory& reference) {
  return relative_error(run, reference, run.positions, reference.positions, centre_distance,
                        kLeastMotion);
}

double trajectory_rotation_error(const Trajectory& run, const Trajectory& reference) {
  return relative_error(run, reference, run.orientations, reference.orientations,
                        rotation_angle_between, kLeastTurn);
}

double largest_motion(const Trajectory& t) {
  return largest_from_start(t.positions, t.bodies.size(), centre_distance);
}

double largest_turn(const Trajectory& t) {
  return largest_from_start(t.orientations, t.bodies.size(), rotation_angle_between);
}

double largest_accumulated_turn(const Trajectory& t) {
  const size_t nb = t.bodies.size();
  double largest = 0.0;
  for (size_t b = 0; b < nb; ++b) {
    double turned = 0.0;
    for (size_t k = 1; k < t.orientations.size() / nb; ++k) {
      const double a =
          rotation_angle_between(t.orientations[(k - 1) * nb + b], t.orientations[k * nb + b]);
      if (!(a <= kLongestSampledTurn)) return std::numeric_limits<double>::quiet_NaN();
      turned += a;
    }
    largest = std::max(largest, turned);
  }
  return largest;
}

bool same_samples(const Trajectory& a, const Trajectory& b) {
  return a.bodies == b.bodies && a.times == b.times && a.positions == b.positions &&
         a.orientations == b.orientations;
}

}  // namespace beamrail
