#include "core/analysis/dense_product.hpp"

namespace beamrail {
namespace {

// One pass over the columns of a (8 at a time: y is loaded and stored once per 8 columns) for
// `kVectors` right-hand sides. Plain loops over i that the compiler vectorizes for each target
// below.
template <int kVectors>
[[gnu::always_inline]] inline void product_kernel(long n, const double* __restrict a,
                                                  const double* __restrict x,
                                                  double* __restrict y) {
  constexpr int kBlock = 8;
  if (n < kBlock) {
    // A few modes (a small scene relinearized often): the blocked loops' set-up would dominate.
    for (int v = 0; v < kVectors; ++v)
      for (long i = 0; i < n; ++i) {
        double s = 0.0;
        for (long k = 0; k < n; ++k) s += a[k * n + i] * x[v * n + k];
        y[v * n + i] = s;
      }
    return;
  }
  for (long i = 0; i < kVectors * n; ++i) y[i] = 0.0;
  long k = 0;
  for (; k + kBlock <= n; k += kBlock) {
    const double* col = a + k * n;
    double p[kVectors][kBlock];
    for (int v = 0; v < kVectors; ++v)
      for (int j = 0; j < kBlock; ++j) p[v][j] = x[v * n + k + j];
    for (long i = 0; i < n; ++i) {
      double s[kVectors];
      for (int v = 0; v < kVectors; ++v) s[v] = y[v * n + i];
      for (int j = 0; j < kBlock; ++j) {
        const double c = col[j * n + i];
        for (int v = 0; v < kVectors; ++v) s[v] += p[v][j] * c;
      }
      for (int v = 0; v < kVectors; ++v) y[v * n + i] = s[v];
    }
  }
  for (; k < n; ++k) {
    const double* col = a + k * n;
    for (int v = 0; v < kVectors; ++v) {
      const double p = x[v * n + k];
      for (long i = 0; i < n; ++i) y[v * n + i] += p * col[i];
    }
  }
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && \
    !defined(BEAMRAIL_NO_MULTIVERSION)
#define BEAMRAIL_CLONES __attribute__((target_clones("avx512f", "arch=haswell", "default")))
#else
#define BEAMRAIL_CLONES
#endif

BEAMRAIL_CLONES void pair_kernel(long n, const double* a, const double* x, double* y) {
  product_kernel<2>(n, a, x, y);
}

BEAMRAIL_CLONES void vector_kernel(long n, const double* a, const double* x, double* y) {
  product_kernel<1>(n, a, x, y);
}

}  // namespace

void multiply_pair(const Eigen::MatrixXd& a, const double* x, double* y) {
  eigen_assert(a.rows() == a.cols());
  pair_kernel(a.rows(), a.data(), x, y);
}

void multiply_vector(const Eigen::MatrixXd& a, const double* x, double* y) {
  eigen_assert(a.rows() == a.cols());
  vector_kernel(a.rows(), a.data(), x, y);
}

}  // namespace beamrail
