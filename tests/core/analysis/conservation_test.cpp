// Conservation laws of free-floating motion: energy, linear and angular momentum, and |q| = 1.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "core/model/beam.hpp"
#include "tests/support/transient_run.hpp"
#include "tests/support/tumbling_pair.hpp"

namespace beamrail {
namespace {

using testing::Snapshot;
using testing::TransientRun;
using testing::tumbling_pair_scene;

struct Momenta {
  Vec3 com, v_com, h;  // centre of mass, its velocity, angular momentum about it
};

Momenta momenta(const Model& model, const Snapshot& s) {
  Momenta out{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  double m = 0;
  for (int i : model.free_bodies) {
    const double mi = model.bodies[i].mass;
    m += mi;
    out.com += mi * s.c[i];
    out.v_com += mi * s.pose[i].v;
  }
  out.com /= m, out.v_com /= m;
  for (int i : model.free_bodies) {
    const Body& b = model.bodies[i];
    out.h += b.mass * (s.c[i] - out.com).cross(s.pose[i].v - out.v_com) +
             s.pose[i].A * (b.inertia * s.w[i]);
  }
  return out;
}

TEST(Conservation, TumblingPairConservesEnergyAndMomenta) {
  for (const std::string formulation : {"energy", "paper"}) {
    const Model model = testing::scene_from_json(tumbling_pair_scene(formulation));
    const TransientRun run = testing::simulate(model, testing::options(1.0, 1e-3, 1e-11, 1e-13));
    ASSERT_TRUE(run.result.ok) << run.result.message;
    const Momenta m0 = momenta(model, run.samples.front());
    const double e0 = run.samples.front().sample.energy();
    double energy_drift = 0, com_error = 0, h_drift = 0, max_phi = 0;
    for (const Snapshot& s : run.samples) {
      const Momenta m = momenta(model, s);
      energy_drift = std::max(energy_drift, std::abs(s.sample.energy() / e0 - 1));
      com_error = std::max(com_error, (m.com - (m0.com + s.sample.t * m0.v_com)).norm());
      h_drift = std::max(h_drift, (m.h - m0.h).norm() / m0.h.norm());
      const ElementFrames<double> f = element_frames(model.beams[0].ends, s.pose[1], s.pose[2],
                                                     rotation_measure(model.beams[0]));
      max_phi = std::max(max_phi, element_angle(f, rotation_measure(model.beams[0])));
    }
    const double final_energy = run.samples.back().sample.energy() / e0 - 1;
    std::printf(
        "%s: 1 s tumbling, max |phi| %.3f rad: max |E/E0 - 1| = %.2e (final %.2e), centre "
        "of mass off uniform motion by %.2e m, max |H - H0|/|H0| = %.2e (%ld steps)\n",
        formulation.c_str(), max_phi, energy_drift, final_energy, com_error, h_drift,
        run.result.stats.steps);
    EXPECT_GT(max_phi, 0.01);  // the beam really deforms by a few hundredths of a radian
    EXPECT_LT(max_phi, 0.1);
    EXPECT_LT(com_error, 1e-10);
    if (formulation == "energy") {
      EXPECT_LT(energy_drift, 1e-7);
      EXPECT_LT(h_drift, 1e-8);
    } else {
      // docs/model.md: the paper's end wrenches are not conservative beyond first order (the
      // prototype lost 5 % in 1 s); it must show here, far above the integration error.
      EXPECT_GT(energy_drift, 1e-4);
    }
  }
}

// A free body spinning about its intermediate principal axis tumbles (it flips over every few
// seconds); over 1e5 steps |q| stays at 1 and the angular momentum is conserved.
TEST(Conservation, IntermediateAxisTumblingKeepsUnitQuaternionAndAngularMomentum) {
  const Model model = testing::scene_from_json(R"({
    "bodies": [{"name": "box", "mass": 1.0, "inertia": [1, 2, 3], "position": [0, 0, 0],
                "angular_velocity": [0.01, 2.0, 0.01]}]})");
  TransientOptions o = testing::options(20.0, 0.01, 1e-11, 1e-13);
  o.integrator.max_step = 20.0 / 1e5;
  const TransientRun run = testing::simulate(model, o);
  ASSERT_TRUE(run.result.ok) << run.result.message;
  const Body& b = model.bodies[1];
  const Vec3 h0 = run.samples.front().pose[1].A * (b.inertia * run.samples.front().w[1]);
  double q_error = 0, h_drift = 0, min_wy = 1e9, max_wy = -1e9;
  for (const Snapshot& s : run.samples) {
    q_error = std::max(q_error, std::abs(s.q[1].norm() - 1));
    h_drift = std::max(h_drift, (s.pose[1].A * (b.inertia * s.w[1]) - h0).norm() / h0.norm());
    min_wy = std::min(min_wy, s.w[1](1));
    max_wy = std::max(max_wy, s.w[1](1));
  }
  std::printf(
      "intermediate axis, %ld steps: max ||q| - 1| = %.2e, max |H - H0|/|H0| = %.2e, "
      "w_y in [%.3f, %.3f]\n",
      run.result.stats.steps, q_error, h_drift, min_wy, max_wy);
  EXPECT_GE(run.result.stats.steps, 100000);
  EXPECT_LT(min_wy, -1.9);  // it did flip over
  EXPECT_LT(q_error, 1e-12);
  EXPECT_LT(h_drift, 1e-8);
}

}  // namespace
}  // namespace beamrail
