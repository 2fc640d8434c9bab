// Runs a transient analysis on a scene and keeps every sample (energies and body states).
#pragma once

#include <algorithm>
#include <vector>

#include "core/analysis/transient.hpp"
#include "tests/support/scenes.hpp"

namespace beamrail::testing {

struct Snapshot {
  TransientSample sample;
  std::vector<Pose<double>> pose;  // per body
  std::vector<Vec4> q;             // raw Euler parameters, as integrated
  std::vector<Vec3> w;             // body-axes angular velocities
};

struct TransientRun {
  TransientResult result;
  std::vector<Snapshot> samples;
};

inline TransientRun simulate(const Model& model, const TransientOptions& options) {
  TransientRun r;
  Data data(model);
  r.result = run_transient(model, options, data, [&r](const TransientSample& s, const Data& d) {
    r.samples.push_back({s, d.pose, d.q, d.w});
  });
  return r;
}

// Largest distance of body b's centre from its reference position over the common samples,
// relative to its largest motion in the reference.
inline double motion_error(const TransientRun& run, const TransientRun& reference, int b) {
  double error = 0.0, motion = 0.0;
  const Vec3 start = reference.samples.front().pose[b].c;
  for (const auto& s : reference.samples) motion = std::max(motion, (s.pose[b].c - start).norm());
  const size_t n = std::min(run.samples.size(), reference.samples.size());
  for (size_t k = 0; k < n; ++k)
    error = std::max(error, (run.samples[k].pose[b].c - reference.samples[k].pose[b].c).norm());
  return error / motion;
}

inline TransientOptions options(double t_end, double output_step, double rtol, double atol) {
  TransientOptions o;
  o.t_end = t_end;
  o.output_step = output_step;
  o.integrator.rtol = rtol;
  o.integrator.atol = atol;
  return o;
}

}  // namespace beamrail::testing
