#include "core/analysis/dense_product.hpp"

#include <omp.h>

#include <algorithm>
#include <cstring>

namespace beamrail {
namespace {

// One pass over the columns of the rows x cols matrix a (8 at a time: y is loaded and stored once
// per 8 columns) for `kVectors` right-hand sides (x: cols x kVectors, y: rows x kVectors, both
// column-major). Plain loops over i that the compiler vectorizes for each target below.
// kSquare: rows == cols, one variable for both (the compiler then keeps the square case's code as
// fast as before the kernel took rectangles: the braced tower's every-mode run was 8 % slower).
// A thread's slab of rows (kSquare false): a and y point to its first row, and their columns lie
// `ld` apart (the whole matrix's rows); otherwise ld == rows.
template <int kVectors, bool kSquare>
[[gnu::always_inline]] inline void product_kernel(long ld_given, long rows, long cols_given,
                                                  const double* __restrict a,
                                                  const double* __restrict x,
                                                  double* __restrict y) {
  const long cols = kSquare ? rows : cols_given;
  const long ld = kSquare ? rows : ld_given;
  constexpr int kBlock = 8;
  if (rows < kBlock && cols < kBlock) {
    // A few modes (a small scene relinearized often): the blocked loops' set-up would dominate.
    for (int v = 0; v < kVectors; ++v)
      for (long i = 0; i < rows; ++i) {
        double s = 0.0;
        for (long k = 0; k < cols; ++k) s += a[k * ld + i] * x[v * cols + k];
        y[v * ld + i] = s;
      }
    return;
  }
  for (int v = 0; v < kVectors; ++v)
    for (long i = 0; i < rows; ++i) y[v * ld + i] = 0.0;
  long k = 0;
  for (; k + kBlock <= cols; k += kBlock) {
    const double* col = a + k * ld;
    double p[kVectors][kBlock];
    for (int v = 0; v < kVectors; ++v)
      for (int j = 0; j < kBlock; ++j) p[v][j] = x[v * cols + k + j];
    for (long i = 0; i < rows; ++i) {
      double s[kVectors];
      for (int v = 0; v < kVectors; ++v) s[v] = y[v * ld + i];
      for (int j = 0; j < kBlock; ++j) {
        const double c = col[j * ld + i];
        for (int v = 0; v < kVectors; ++v) s[v] += p[v][j] * c;
      }
      for (int v = 0; v < kVectors; ++v) y[v * ld + i] = s[v];
    }
  }
  for (; k < cols; ++k) {
    const double* col = a + k * ld;
    for (int v = 0; v < kVectors; ++v) {
      const double p = x[v * cols + k];
      for (long i = 0; i < rows; ++i) y[v * ld + i] += p * col[i];
    }
  }
}

// y = a x for kVectors right-hand sides, written with the compiler's vector types (8 doubles: one
// AVX-512 register, two AVX2 ones, four SSE2 ones) where product_kernel's plain loops do not
// vectorize for six: per 8 rows, the kVectors partial sums stay in registers over kBlock matrix
// columns. Measured at n = 1038 on the reference machine: three pairs in one pass 302 us, three
// passes of product_kernel 502 us.
template <int kVectors>
[[gnu::always_inline]] inline void wide_kernel(long ld, long rows, long cols,
                                               const double* __restrict a,
                                               const double* __restrict x, double* __restrict y) {
  typedef double Lanes __attribute__((vector_size(64)));
  constexpr int kBlock = 8;
  const long body = rows - rows % 8;
  for (int v = 0; v < kVectors; ++v)
    for (long i = 0; i < rows; ++i) y[v * ld + i] = 0.0;
  long k = 0;
  for (; k + kBlock <= cols; k += kBlock) {
    double p[kVectors][kBlock];
    for (int v = 0; v < kVectors; ++v)
      for (int j = 0; j < kBlock; ++j) p[v][j] = x[v * cols + k + j];
    const double* col = a + k * ld;
    for (long i = 0; i < body; i += 8) {
      Lanes s[kVectors];
      for (int v = 0; v < kVectors; ++v) std::memcpy(&s[v], y + v * ld + i, sizeof(Lanes));
      for (int j = 0; j < kBlock; ++j) {
        Lanes c;
        std::memcpy(&c, col + j * ld + i, sizeof c);
        for (int v = 0; v < kVectors; ++v) s[v] += p[v][j] * c;
      }
      for (int v = 0; v < kVectors; ++v) std::memcpy(y + v * ld + i, &s[v], sizeof(Lanes));
    }
    for (long i = body; i < rows; ++i)
      for (int j = 0; j < kBlock; ++j)
        for (int v = 0; v < kVectors; ++v) y[v * ld + i] += p[v][j] * col[j * ld + i];
  }
  for (; k < cols; ++k)
    for (int v = 0; v < kVectors; ++v) {
      const double p = x[v * cols + k];
      for (long i = 0; i < rows; ++i) y[v * ld + i] += p * a[k * ld + i];
    }
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && \
    !defined(BEAMRAIL_NO_MULTIVERSION)
#define BEAMRAIL_CLONES __attribute__((target_clones("avx512f", "arch=haswell", "default")))
#else
#define BEAMRAIL_CLONES
#endif

// ld: the whole matrix's rows; rows: those of this slab (a and y point to its first row).
BEAMRAIL_CLONES void pair_kernel(long ld, long rows, long cols, const double* a, const double* x,
                                 double* y) {
  if (rows == cols && rows == ld)
    product_kernel<2, true>(ld, rows, cols, a, x, y);
  else
    product_kernel<2, false>(ld, rows, cols, a, x, y);
}

BEAMRAIL_CLONES void six_kernel(long ld, long rows, long cols, const double* a, const double* x,
                                double* y) {
  wide_kernel<6>(ld, rows, cols, a, x, y);
}

BEAMRAIL_CLONES void vector_kernel(long ld, long rows, long cols, const double* a, const double* x,
                                   double* y) {
  if (rows == cols && rows == ld)
    product_kernel<1, true>(ld, rows, cols, a, x, y);
  else
    product_kernel<1, false>(ld, rows, cols, a, x, y);
}

// Below this many multiply-adds a product runs on one thread: a parallel region's start and
// join (microseconds) would cost more than the second thread saves.
constexpr long kThreadedWork = 1L << 17;

// The threads a product of `work` multiply-adds takes: the run's (-j, OMP_NUM_THREADS), or one
// inside a parallel region (a batch's designs on their threads) or for small work.
int product_threads(long work) {
  if (work < kThreadedWork || omp_in_parallel()) return 1;
  return std::max(1, omp_get_max_threads());
}

// f(begin, end) over [0, n) in one contiguous slab per thread, slabs a multiple of 8 long (the
// kernels' blocking), so that each entry of the result is computed by one thread in the same
// order as on one: a product's result does not depend on the thread count.
template <class F>
void over_slabs(long n, long work, F f) {
  const int threads = static_cast<int>(std::min<long>(product_threads(work), (n + 7) / 8));
  if (threads <= 1) {
    f(0L, n);
    return;
  }
  const long slab = ((n + threads - 1) / threads + 7) / 8 * 8;
#pragma omp parallel for num_threads(threads) schedule(static, 1)
  for (int t = 0; t < threads; ++t) {
    const long begin = std::min(n, t * slab), end = std::min(n, begin + slab);
    if (begin < end) f(begin, end);
  }
}

}  // namespace

void multiply_pair(const Eigen::MatrixXd& a, const double* x, double* y) {
  const long ld = a.rows(), cols = a.cols();
  over_slabs(ld, 2 * ld * cols, [&](long begin, long end) {
    pair_kernel(ld, end - begin, cols, a.data() + begin, x, y + begin);
  });
}

void multiply_three_pairs(const Eigen::MatrixXd& a, const double* x, double* y) {
  const long ld = a.rows(), cols = a.cols();
  over_slabs(ld, 6 * ld * cols, [&](long begin, long end) {
    six_kernel(ld, end - begin, cols, a.data() + begin, x, y + begin);
  });
}

void multiply_vector(const Eigen::MatrixXd& a, const double* x, double* y) {
  const long ld = a.rows(), cols = a.cols();
  over_slabs(ld, ld * cols, [&](long begin, long end) {
    vector_kernel(ld, end - begin, cols, a.data() + begin, x, y + begin);
  });
}

void multiply_transposed(const Eigen::MatrixXd& a, const double* x, double* y) {
  const long rows = a.rows(), cols = a.cols();
  const Eigen::Map<const Eigen::VectorXd> v(x, rows);
  over_slabs(cols, rows * cols, [&](long begin, long end) {
    // Eigen's product with the transpose (dot products, its fastest form here).
    Eigen::Map<Eigen::VectorXd>(y + begin, end - begin).noalias() =
        a.middleCols(begin, end - begin).transpose() * v;
  });
}

}  // namespace beamrail
