// The modal method's dense products (core/analysis/dense_product.hpp) on one thread and on two:
// the braced tower's square basis (1,038 modes), the reference cantilever's in 100 segments
// (600), a small one below the threshold of threads (240), and a band's n x m basis (6,000 x 95).
// Arguments: rows, columns, threads.
#include <benchmark/benchmark.h>

#include <Eigen/Core>

#include "core/analysis/dense_product.hpp"

namespace beamrail {
namespace {

// y = a x for kVectors right-hand sides by `multiply` (multiply_pair or multiply_three_pairs).
template <int kVectors, void (*multiply)(const Eigen::MatrixXd&, const double*, double*)>
void Columns(benchmark::State& state) {
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(state.range(0), state.range(1));
  const Eigen::MatrixXd x = Eigen::MatrixXd::Random(a.cols(), kVectors);
  Eigen::MatrixXd y(a.rows(), kVectors);
  const ProductThreads threads(static_cast<int>(state.range(2)));
  for (auto _ : state) {
    multiply(a, x.data(), y.data());
    benchmark::DoNotOptimize(y.data());
  }
}

void Transposed(benchmark::State& state) {
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(state.range(0), state.range(1));
  const Eigen::VectorXd x = Eigen::VectorXd::Random(a.rows());
  Eigen::VectorXd y(a.cols());
  const ProductThreads threads(static_cast<int>(state.range(2)));
  for (auto _ : state) {
    multiply_transposed(a, x.data(), y.data());
    benchmark::DoNotOptimize(y.data());
  }
}

// t = a^T g, then y = a x with x from t mode by mode (multiply_transposed_then; kVectors 2 or 6):
// a stage of the modal method, against Transposed and Pair (or ThreePairs) apart.
void SetRows(void* context, long begin, long end) {
  auto* x = static_cast<Eigen::MatrixXd*>(context);
  for (long k = begin; k < end; ++k) x->row(k).setConstant(0.5 * k);
}

template <int kVectors>
void TransposedThen(benchmark::State& state) {
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(state.range(0), state.range(1));
  const Eigen::VectorXd g = Eigen::VectorXd::Random(a.rows());
  Eigen::VectorXd t(a.cols());
  Eigen::MatrixXd x(a.cols(), kVectors), y(a.rows(), kVectors);
  const ProductThreads threads(static_cast<int>(state.range(2)));
  for (auto _ : state) {
    multiply_transposed_then(a, g.data(), t.data(), SetRows, &x, kVectors, x.data(), y.data());
    benchmark::DoNotOptimize(y.data());
  }
}

void Sizes(benchmark::internal::Benchmark* b) {
  for (auto [rows, cols] : {std::pair{240L, 240L}, {600L, 600L}, {1038L, 1038L}, {6000L, 95L}})
    for (long threads : {1L, 2L}) b->Args({rows, cols, threads});
  b->UseRealTime();
}

BENCHMARK(Columns<2, multiply_pair>)->Name("Pair")->Apply(Sizes);
BENCHMARK(Columns<6, multiply_three_pairs>)->Name("ThreePairs")->Apply(Sizes);
BENCHMARK(Transposed)->Apply(Sizes);
BENCHMARK(TransposedThen<2>)->Name("TransposedThenPair")->Apply(Sizes);
BENCHMARK(TransposedThen<6>)->Name("TransposedThenThreePairs")->Apply(Sizes);

}  // namespace
}  // namespace beamrail

BENCHMARK_MAIN();
