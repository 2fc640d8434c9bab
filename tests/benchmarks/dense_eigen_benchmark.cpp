// The dense symmetric generalized eigenproblem K x = w^2 M x of the reference cantilever in N
// segments (6 N dof) by Eigen's QL iteration and by LAPACK's dsygvd
// (core/analysis/dense_eigen.hpp): the figures behind kLapackEigenFrom. Arguments: segments, driver
// (0 Eigen, 1 LAPACK).
#include <benchmark/benchmark.h>

#include "core/analysis/dense_eigen.hpp"
#include "core/analysis/modal_analysis.hpp"
#include "tests/benchmarks/reference_problem.hpp"
#include "tests/support/pencil.hpp"

namespace beamrail {
namespace {

void Generalized(benchmark::State& state) {
  const auto [k, m] =
      testing::pencil_at_rest(bench::reference_model(static_cast<int>(state.range(0))));
  const DenseEigenDriver driver =
      state.range(1) ? DenseEigenDriver::kLapack : DenseEigenDriver::kEigen;
  Eigen::VectorXd values;
  Eigen::MatrixXd vectors;
  for (auto _ : state) {
    if (!generalized_symmetric_eigen(k, m, values, vectors, driver))
      state.SkipWithError("the eigensolver failed");
    benchmark::DoNotOptimize(vectors.data());
  }
  state.counters["dof"] = static_cast<double>(k.rows());
}

// solve_dense_eigenproblem (core/analysis/modal_analysis.hpp): the direct problem and, the
// cantilever's spectrum spanning more than 6 decades, the inverse one for its lower half.
void DirectAndInverse(benchmark::State& state) {
  const auto [k, m] =
      testing::pencil_at_rest(bench::reference_model(static_cast<int>(state.range(0))));
  Eigen::VectorXd values;
  Eigen::MatrixXd vectors;
  for (auto _ : state) {
    if (!solve_dense_eigenproblem(k, m, values, vectors))
      state.SkipWithError("the eigensolver failed");
    benchmark::DoNotOptimize(vectors.data());
  }
  state.counters["dof"] = static_cast<double>(k.rows());
}

BENCHMARK(DirectAndInverse)->Arg(40)->Arg(173)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(Generalized)
    ->ArgsProduct({{5, 10, 17, 25, 40, 100, 173}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace beamrail

BENCHMARK_MAIN();
