// Element kernels: force evaluation and force + exact Jacobian per beam (issue targets: force
// <= 100 ns paper, <= 300 ns energy; force + Jacobian <= 2 us).
#include <benchmark/benchmark.h>

#include "core/model/beam.hpp"
#include "core/model/element_tangent.hpp"
#include "core/model/rail.hpp"
#include "tests/support/random_elements.hpp"

namespace beamrail {
namespace {

struct Case {
  Beam beam;
  Pose<double> b1, b2;
};

Case make_case(Formulation f, double damping) {
  testing::Random rng(3);
  Case c;
  c.b1 = testing::pose(rng.vec3(1.0), rng.rotation());
  c.b2 = testing::pose(rng.vec3(1.0) + Vec3(2, 0, 0), rng.rotation());
  c.beam.ends = testing::make_ends(c.b1.u + rng.vec3(0.2), c.b2.u + rng.vec3(0.2),
                                   c.b1.u + rng.vec3(1.0), c.b1, c.b2);
  c.beam.ea = 2.1e7, c.beam.gj = 113, c.beam.eiy = 175, c.beam.eiz = 175;
  c.beam.formulation = f;
  c.beam.damping = damping;
  c.b2 = testing::perturbed(c.b2, rng.vec3(1e-3), rng.vec3(1e-2));
  c.b2.v = rng.vec3(1.0), c.b2.omega = rng.vec3(1.0);
  return c;
}

void BeamForce(benchmark::State& state, Formulation f) {
  const Case c = make_case(f, 0.0);
  for (auto _ : state) {
    Vec6 w1 = Vec6::Zero(), w2 = Vec6::Zero();
    benchmark::DoNotOptimize(beam_wrenches(c.beam, c.b1, c.b2, w1, w2));
    benchmark::DoNotOptimize(w1);
    benchmark::DoNotOptimize(w2);
  }
}
BENCHMARK_CAPTURE(BeamForce, paper, Formulation::kPaper);
BENCHMARK_CAPTURE(BeamForce, energy, Formulation::kEnergy);

void BeamForceAndJacobian(benchmark::State& state, Formulation f, double damping) {
  const Case c = make_case(f, damping);
  const auto kernel = [&c](const Pose<Ad12>& b1, const Pose<Ad12>& b2, Vec6T<Ad12>& w1,
                           Vec6T<Ad12>& w2) { beam_wrenches(c.beam, b1, b2, w1, w2); };
  for (auto _ : state) {
    Vec6 w1 = Vec6::Zero(), w2 = Vec6::Zero();
    beam_wrenches(c.beam, c.b1, c.b2, w1, w2);
    Mat12 jx = element_jacobian(seed_configuration(c.b1, 0), seed_configuration(c.b2, 6), kernel);
    benchmark::DoNotOptimize(jx);
    if (damping > 0) {
      Mat12 jv = element_jacobian(seed_velocity(c.b1, 0), seed_velocity(c.b2, 6), kernel);
      benchmark::DoNotOptimize(jv);
    }
    benchmark::DoNotOptimize(w1);
  }
}
BENCHMARK_CAPTURE(BeamForceAndJacobian, ad_paper, Formulation::kPaper, 0.0);
BENCHMARK_CAPTURE(BeamForceAndJacobian, ad_energy, Formulation::kEnergy, 0.0);
BENCHMARK_CAPTURE(BeamForceAndJacobian, ad_energy_damped, Formulation::kEnergy, 1e-4);

// The production path for undamped elements: forces plus the closed-form Jacobian.
void BeamForceAndClosedFormJacobian(benchmark::State& state, Formulation f) {
  const Case c = make_case(f, 0.0);
  for (auto _ : state) {
    Vec6 w1 = Vec6::Zero(), w2 = Vec6::Zero();
    beam_wrenches(c.beam, c.b1, c.b2, w1, w2);
    const Mat12 j = configuration_jacobian(
        element_frames(c.beam.ends, c.b1, c.b2, rotation_measure(c.beam)), f,
        rotation_measure(c.beam), [&c](const Vec6T<Ad6>& s) { return beam_law(c.beam, s); });
    benchmark::DoNotOptimize(j);
    benchmark::DoNotOptimize(w1);
  }
}
BENCHMARK_CAPTURE(BeamForceAndClosedFormJacobian, paper, Formulation::kPaper);
BENCHMARK_CAPTURE(BeamForceAndClosedFormJacobian, energy, Formulation::kEnergy);

}  // namespace
}  // namespace beamrail

BENCHMARK_MAIN();
