// Right-hand side and Jacobian assembly for chains of 10 ... 10,000 bodies (the reference
// cantilever split into that many segments), per call.
#include <benchmark/benchmark.h>

#include <vector>

#include "core/analysis/ode_system.hpp"
#include "core/analysis/sparse_structure.hpp"
#include "core/model/dynamics.hpp"
#include "tests/benchmarks/reference_problem.hpp"

namespace beamrail {
namespace {

struct Chain {
  Model model;
  std::vector<double> y, ydot;
  explicit Chain(int n) : model(bench::reference_model(n)) {
    y.resize(model.n_states);
    ydot.resize(model.n_states);
    initial_state(model, y.data());
    // A small deformation so that nothing is exactly zero.
    for (int k = 0; k < model.n_free(); ++k) y[13 * k + 1] -= 1e-4 * k * k / model.n_free();
  }
};

void RightHandSide(benchmark::State& state) {
  Chain c(static_cast<int>(state.range(0)));
  Data data(c.model);
  for (auto _ : state) {
    state_derivative(c.model, data, 0.0, c.y.data(), c.ydot.data());
    benchmark::DoNotOptimize(c.ydot.data());
  }
  state.counters["bodies"] = c.model.n_free();
  state.counters["ns_per_body"] = benchmark::Counter(
      static_cast<double>(c.model.n_free()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(RightHandSide)->Arg(10)->Arg(100)->Arg(1000)->Arg(10000);

void JacobianBlocks(benchmark::State& state) {
  Chain c(static_cast<int>(state.range(0)));
  Data data(c.model);
  std::vector<Mat13> blocks;
  for (auto _ : state) {
    state_jacobian_blocks(c.model, data, 0.0, c.y.data(), blocks);
    benchmark::DoNotOptimize(blocks.data());
  }
  state.counters["bodies"] = c.model.n_free();
}
BENCHMARK(JacobianBlocks)->Arg(10)->Arg(100)->Arg(1000)->Arg(10000);

void SparsePatternBuild(benchmark::State& state) {
  Chain c(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(make_jacobian_pattern(c.model));
}
BENCHMARK(SparsePatternBuild)->Arg(10)->Arg(10000);

// What a design of an already seen topology saves: the pattern and KLU's symbolic analysis
// (SparseStructure) against a lookup in the cache (comparing the topology).
void SparseStructureAnalysis(benchmark::State& state) {
  Chain c(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    SparseStructure s(c.model);
    benchmark::DoNotOptimize(s.symbolic());
  }
  state.counters["bodies"] = c.model.n_free();
}
BENCHMARK(SparseStructureAnalysis)
    ->Arg(10)
    ->Arg(100)
    ->Arg(1000)
    ->Arg(10000)
    ->Unit(benchmark::kMicrosecond);

void SparseStructureCacheHit(benchmark::State& state) {
  Chain c(static_cast<int>(state.range(0)));
  SparseStructureCache cache;
  cache.get(c.model);
  for (auto _ : state) benchmark::DoNotOptimize(cache.get(c.model));
  state.counters["bodies"] = c.model.n_free();
}
BENCHMARK(SparseStructureCacheHit)
    ->Arg(10)
    ->Arg(100)
    ->Arg(1000)
    ->Arg(10000)
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace beamrail

BENCHMARK_MAIN();
