// Runs a transient analysis on a scene and keeps every sample (energies and body states).
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include "core/analysis/transient.hpp"
#include "core/model/rotation.hpp"
#include "tests/support/scenes.hpp"

namespace beamrail::testing {

struct Snapshot {
  TransientSample sample;
  std::vector<Pose<double>> pose;  // per body
  std::vector<Vec3> c;             // centre of mass per body, global [m]
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
  r.result =
      run_transient(model, options, data, [&r, &model](const TransientSample& s, const Data& d) {
        std::vector<Vec3> c(model.bodies.size());
        for (size_t i = 0; i < c.size(); ++i) c[i] = centre(model, d, static_cast<int>(i));
        r.samples.push_back({s, d.pose, std::move(c), d.q, d.w});
      });
  return r;
}

// For body b over the common samples: the largest distance between the runs' centres and the
// largest distance the body moved in the reference.
struct BodyDeviation {
  double error = 0.0, motion = 0.0;
};
inline BodyDeviation body_deviation(const TransientRun& run, const TransientRun& reference, int b) {
  BodyDeviation d;
  const Vec3 start = reference.samples.front().c[b];
  for (const auto& s : reference.samples) d.motion = std::max(d.motion, (s.c[b] - start).norm());
  const size_t n = std::min(run.samples.size(), reference.samples.size());
  for (size_t k = 0; k < n; ++k)
    d.error = std::max(d.error, (run.samples[k].c[b] - reference.samples[k].c[b]).norm());
  return d;
}

// Largest distance of body b's centre from its reference position over the common samples,
// relative to its largest motion in the reference.
inline double motion_error(const TransientRun& run, const TransientRun& reference, int b) {
  const BodyDeviation d = body_deviation(run, reference, b);
  return d.error / d.motion;
}

// Largest distance between the runs' free-body centres over the common samples, relative to the
// largest distance a body moved in the reference (the work-precision study's measure).
inline double run_error(const Model& model, const TransientRun& run,
                        const TransientRun& reference) {
  double error = 0.0, motion = 0.0;
  for (int b : model.free_bodies) {
    const BodyDeviation d = body_deviation(run, reference, b);
    error = std::max(error, d.error);
    motion = std::max(motion, d.motion);
  }
  return error / motion;
}

// Largest angle between the runs' free-body orientations over the common samples, relative to
// the largest angle a body turned in the reference (work_precision.csv's rotation_error).
inline double run_rotation_error(const Model& model, const TransientRun& run,
                                 const TransientRun& reference) {
  double error = 0.0, turn = 0.0;
  const size_t n = std::min(run.samples.size(), reference.samples.size());
  for (int b : model.free_bodies) {
    for (const auto& s : reference.samples)
      turn = std::max(turn, rotation_angle_between(s.q[b], reference.samples.front().q[b]));
    for (size_t k = 0; k < n; ++k)
      error =
          std::max(error, rotation_angle_between(run.samples[k].q[b], reference.samples[k].q[b]));
  }
  return error / turn;
}

inline TransientOptions options(double t_end, double output_step, double rtol, double atol) {
  TransientOptions o;
  o.t_end = t_end;
  o.output_step = output_step;
  o.integrator.rtol = rtol;
  o.integrator.atol = atol;
  return o;
}

// A run of `method` ("auto", "modal", "bdf" ...) at rtol 1e-8, atol 1e-10, stopped after 60 s
// (a guard: the range tests' runs end in well under a second).
inline TransientOptions range_options(const std::string& method, double t_end, double output_step) {
  TransientOptions o = options(t_end, output_step, 1e-8, 1e-10);
  o.integrator.method = *method_from_name(method);
  o.max_seconds = 60.0;
  return o;
}

// A tight reference run: explicit Verner 8(7) at rtol (atol 1e-2 rtol).
inline TransientRun tight(const Model& model, double t_end, double output_step,
                          double rtol = 1e-11) {
  TransientOptions o = options(t_end, output_step, rtol, 1e-2 * rtol);
  o.integrator.method = IntegratorMethod::kErk;
  o.integrator.table = "VERNER_8_5_6";
  return simulate(model, o);
}

// A run of `method` ("auto", "modal", "bdf" ...) at rtol (atol 1e-2 rtol), with the modal
// method's band `band` [Hz] (0: none).
inline TransientRun run_with(const Model& model, const std::string& method, double t_end,
                             double output_step, double rtol, double band = 0.0) {
  TransientOptions o = options(t_end, output_step, rtol, 1e-2 * rtol);
  o.integrator.method = *method_from_name(method);
  o.integrator.max_frequency_hz = band;
  return simulate(model, o);
}

}  // namespace beamrail::testing
