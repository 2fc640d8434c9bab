#include "core/analysis/dense_product.hpp"

#include <cstring>

namespace beamrail {
namespace {

// One pass over the columns of the rows x cols matrix a (8 at a time: y is loaded and stored once
// per 8 columns) for `kVectors` right-hand sides (x: cols x kVectors, y: rows x kVectors, both
// column-major). Plain loops over i that the compiler vectorizes for each target below.
// kSquare: rows == cols, one variable for both (the compiler then keeps the square case's code as
// fast as before the kernel took rectangles: the braced tower's every-mode run was 8 % slower).
template <int kVectors, bool kSquare>
[[gnu::always_inline]] inline void product_kernel(long rows, long cols_given,
                                                  const double* __restrict a,
                                                  const double* __restrict x,
                                                  double* __restrict y) {
  const long cols = kSquare ? rows : cols_given;
  constexpr int kBlock = 8;
  if (rows < kBlock && cols < kBlock) {
    // A few modes (a small scene relinearized often): the blocked loops' set-up would dominate.
    for (int v = 0; v < kVectors; ++v)
      for (long i = 0; i < rows; ++i) {
        double s = 0.0;
        for (long k = 0; k < cols; ++k) s += a[k * rows + i] * x[v * cols + k];
        y[v * rows + i] = s;
      }
    return;
  }
  for (long i = 0; i < kVectors * rows; ++i) y[i] = 0.0;
  long k = 0;
  for (; k + kBlock <= cols; k += kBlock) {
    const double* col = a + k * rows;
    double p[kVectors][kBlock];
    for (int v = 0; v < kVectors; ++v)
      for (int j = 0; j < kBlock; ++j) p[v][j] = x[v * cols + k + j];
    for (long i = 0; i < rows; ++i) {
      double s[kVectors];
      for (int v = 0; v < kVectors; ++v) s[v] = y[v * rows + i];
      for (int j = 0; j < kBlock; ++j) {
        const double c = col[j * rows + i];
        for (int v = 0; v < kVectors; ++v) s[v] += p[v][j] * c;
      }
      for (int v = 0; v < kVectors; ++v) y[v * rows + i] = s[v];
    }
  }
  for (; k < cols; ++k) {
    const double* col = a + k * rows;
    for (int v = 0; v < kVectors; ++v) {
      const double p = x[v * cols + k];
      for (long i = 0; i < rows; ++i) y[v * rows + i] += p * col[i];
    }
  }
}

// y = a x for kVectors right-hand sides, written with the compiler's vector types (8 doubles: one
// AVX-512 register, two AVX2 ones, four SSE2 ones) where product_kernel's plain loops do not
// vectorize for six: per 8 rows, the kVectors partial sums stay in registers over kBlock matrix
// columns. Measured at n = 1038 on the reference machine: three pairs in one pass 302 us, three
// passes of product_kernel 502 us.
template <int kVectors>
[[gnu::always_inline]] inline void wide_kernel(long rows, long cols, const double* __restrict a,
                                               const double* __restrict x, double* __restrict y) {
  typedef double Lanes __attribute__((vector_size(64)));
  constexpr int kBlock = 8;
  const long body = rows - rows % 8;
  for (long i = 0; i < kVectors * rows; ++i) y[i] = 0.0;
  long k = 0;
  for (; k + kBlock <= cols; k += kBlock) {
    double p[kVectors][kBlock];
    for (int v = 0; v < kVectors; ++v)
      for (int j = 0; j < kBlock; ++j) p[v][j] = x[v * cols + k + j];
    const double* col = a + k * rows;
    for (long i = 0; i < body; i += 8) {
      Lanes s[kVectors];
      for (int v = 0; v < kVectors; ++v) std::memcpy(&s[v], y + v * rows + i, sizeof(Lanes));
      for (int j = 0; j < kBlock; ++j) {
        Lanes c;
        std::memcpy(&c, col + j * rows + i, sizeof c);
        for (int v = 0; v < kVectors; ++v) s[v] += p[v][j] * c;
      }
      for (int v = 0; v < kVectors; ++v) std::memcpy(y + v * rows + i, &s[v], sizeof(Lanes));
    }
    for (long i = body; i < rows; ++i)
      for (int j = 0; j < kBlock; ++j)
        for (int v = 0; v < kVectors; ++v) y[v * rows + i] += p[v][j] * col[j * rows + i];
  }
  for (; k < cols; ++k)
    for (int v = 0; v < kVectors; ++v) {
      const double p = x[v * cols + k];
      for (long i = 0; i < rows; ++i) y[v * rows + i] += p * a[k * rows + i];
    }
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && \
    !defined(BEAMRAIL_NO_MULTIVERSION)
#define BEAMRAIL_CLONES __attribute__((target_clones("avx512f", "arch=haswell", "default")))
#else
#define BEAMRAIL_CLONES
#endif

BEAMRAIL_CLONES void pair_kernel(long rows, long cols, const double* a, const double* x,
                                 double* y) {
  if (rows == cols)
    product_kernel<2, true>(rows, cols, a, x, y);
  else
    product_kernel<2, false>(rows, cols, a, x, y);
}

BEAMRAIL_CLONES void six_kernel(long rows, long cols, const double* a, const double* x, double* y) {
  wide_kernel<6>(rows, cols, a, x, y);
}

BEAMRAIL_CLONES void vector_kernel(long rows, long cols, const double* a, const double* x,
                                   double* y) {
  if (rows == cols)
    product_kernel<1, true>(rows, cols, a, x, y);
  else
    product_kernel<1, false>(rows, cols, a, x, y);
}

}  // namespace

void multiply_pair(const Eigen::MatrixXd& a, const double* x, double* y) {
  pair_kernel(a.rows(), a.cols(), a.data(), x, y);
}

void multiply_three_pairs(const Eigen::MatrixXd& a, const double* x, double* y) {
  six_kernel(a.rows(), a.cols(), a.data(), x, y);
}

void multiply_vector(const Eigen::MatrixXd& a, const double* x, double* y) {
  vector_kernel(a.rows(), a.cols(), a.data(), x, y);
}

}  // namespace beamrail
