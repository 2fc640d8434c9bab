// Body trajectories of a transient run, kept to compare runs: the accuracy a run achieved against a
// tighter one (work-precision studies, "verify").
#pragma once

#include <vector>

#include "core/analysis/transient.hpp"

namespace beamrail {

struct Trajectory {
  std::vector<int> bodies;         // the scene's own free bodies
  std::vector<double> times;       // [s]
  std::vector<Vec3> positions;     // displacement of each body's centre at each time, time-major
  std::vector<Vec4> orientations;  // each body's Euler parameters (body -> global), like positions
  long stride = 1;                 // keeps every stride-th sample recorded, from the first
  long seen = 0;                   // samples recorded so far, kept or not
  void record(const TransientSample& sample, const Data& data);
};

// The most body samples (one body at one time: 56 bytes) a trajectory keeps: a run of more
// samples keeps every stride-th, so that the two trajectories of a verified run stay within 112
// MiB whatever the bodies and rows (for a chain of 1,000 links over 100,000 rows they would take
// 11 GB).
inline constexpr long kTrajectoryBodySamples = 1L << 20;

// Starts an empty trajectory of the model's scene bodies for a run of `rows` samples (0: keep
// every sample).
Trajectory trajectory_of(const Model& model, long rows = 0);

// The largest distance between the runs' body centres over the common times, relative to the
// largest distance a reference body moved from its start; NaN when the runs share no time or no
// reference body moves more than kLeastMotion (rounding, which a ratio would turn into an error
// of any size).
inline constexpr double kLeastMotion = 1e-12;  // [m]
double trajectory_error(const Trajectory& run, const Trajectory& reference);

// The same for orientations: the largest angle between the runs' orientations of a body over the
// common times, relative to the largest angle a reference body turned from its start (both the
// angles of relative rotations, at most pi); NaN when nothing can be compared, an angle is not
// finite, or no reference body turns more than kLeastTurn (a body that does not turn has angles
// of rounding, 1e-20 rad and less, which a ratio would make an error of order one). A run wrong
// only in its rotations (a spinning body's phase) shows here, not in the centres.
inline constexpr double kLeastTurn = 1e-9;  // [rad]
double trajectory_rotation_error(const Trajectory& run, const Trajectory& reference);

// The largest distance a body's centre moved from its start [m], and the largest angle a body
// turned from its start [rad; the angle of the relative rotation, at most pi], over the samples.
double largest_motion(const Trajectory& t);
double largest_turn(const Trajectory& t);

// The largest angle a body turned along its samples [rad]: the sum of the angles between its
// successive orientations (a spin's whole turn, not capped at pi); NaN when two successive samples
// are more than kLongestSampledTurn apart (they may then be a turn of 2 pi more), or an angle is
// not finite.
inline constexpr double kLongestSampledTurn = 3.0;  // [rad]
double largest_accumulated_turn(const Trajectory& t);

// Whether the two trajectories hold the same samples, bit for bit.
bool same_samples(const Trajectory& a, const Trajectory& b);

}  // namespace beamrail
