#include "core/analysis/dense_product.hpp"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace beamrail {
namespace {

thread_local int product_thread_budget = 1;
std::atomic<long> products_shared{0};
std::atomic<int> largest_team{1};

// Counts a product that ran on a team of n threads (called by one of them).
void count_team(long n) {
  if (n <= 1) return;
  ++products_shared;
  int seen = largest_team.load();
  while (seen < n && !largest_team.compare_exchange_weak(seen, static_cast<int>(n))) {
  }
}

// The threads for a product of a rows x cols matrix, `parts` being the rows or columns shared out.
int threads_for(long rows, long cols, long parts) {
#ifdef _OPENMP
  if (rows * cols >= kParallelProductSize)
    return static_cast<int>(std::clamp<long>(parts / 64, 1, product_thread_budget));
#else
  (void)rows, (void)cols, (void)parts;
#endif
  return 1;
}

// The kernels' pieces. y = a x for kVectors right-hand sides (x: cols x kVectors, y: rows x
// kVectors, column-major) is summed per kLanes rows over kBlock = 8 matrix columns at a time, the
// kVectors partial sums in registers (y is loaded and stored once per 8 columns), written with
// the compiler's vector types. kLanes: 8 doubles (one AVX-512 register, two AVX2 ones) or 4 (one
// AVX2 register). Measured at n = 1038 on the reference machine (AVX-512): three pairs in one
// pass (8 lanes) 302 us, three passes of plain loops that the compiler vectorized 502 us; on an
// AVX2 machine (AMD EPYC) a pair with 4 lanes 230 us, with those plain loops 350 us, one vector
// 179 against 183 us (and 78 against 83 us at 6,000 x 95, 6.3 against 8.5 us at n = 240). Every
// entry of y is summed over the columns in their order whatever the blocking, so a pass that
// computes x on its way (transposed_then) gives the bits of one that is given it. Other shapes
// of the pair on the AVX-512 machine (a standalone copy, medians of 15): two partial sums per
// vector, 16 columns per block, 16 rows per step took 7.1 to 9.1 us against 7.2 at n = 240 (in
// L2) and 153 to 157 against 162 us at n = 1,040: about 16 and 14 GFMA/s, near what its FMA
// units give at the 2.4 to 3.4 GHz this machine runs at. Kept as it is. Three pairs in one pass
// on the AVX2 machine (n = 1,038; a standalone driver of this file, medians of 21, three rounds
// each, 2026-11-30): in 8 lanes (two registers each, 48 broadcasts) 760 to 786 us against 583
// to 756 us for three pair passes; in 4 lanes 815 to 877 us as GCC at -O3 compiles the loops
// over the vectors and the block's columns, 487 to 526 us with them unrolled by pragma. So AVX2
// takes one pass too, in 4 lanes, unrolled.
constexpr int kBlock = 8;

template <int kVectors>
[[gnu::always_inline]] inline void zero(long rows, double* __restrict y, long ldy) {
  for (int v = 0; v < kVectors; ++v)
    for (long i = 0; i < rows; ++i) y[v * ldy + i] = 0.0;
}

// y += a(:, k .. k + 7) x(k .. k + 7, :), `col` pointing at column k.
template <int kVectors, int kLanes>
[[gnu::always_inline]] inline void add_block(long rows, const double* __restrict col, long lda,
                                             const double* x, long cols, long k,
                                             double* __restrict y, long ldy) {
  typedef double Lanes __attribute__((vector_size(8 * kLanes)));
  const long body = rows - rows % kLanes;
  double p[kVectors][kBlock];
#pragma GCC unroll 8
  for (int v = 0; v < kVectors; ++v)
#pragma GCC unroll 8
    for (int j = 0; j < kBlock; ++j) p[v][j] = x[v * cols + k + j];
  for (long i = 0; i < body; i += kLanes) {
    Lanes s[kVectors];
#pragma GCC unroll 8
    for (int v = 0; v < kVectors; ++v) std::memcpy(&s[v], y + v * ldy + i, sizeof(Lanes));
#pragma GCC unroll 8
    for (int j = 0; j < kBlock; ++j) {
      Lanes c;
      std::memcpy(&c, col + j * lda + i, sizeof c);
#pragma GCC unroll 8
      for (int v = 0; v < kVectors; ++v) s[v] += p[v][j] * c;
    }
#pragma GCC unroll 8
    for (int v = 0; v < kVectors; ++v) std::memcpy(y + v * ldy + i, &s[v], sizeof(Lanes));
  }
  for (long i = body; i < rows; ++i)
    for (int j = 0; j < kBlock; ++j)
      for (int v = 0; v < kVectors; ++v) y[v * ldy + i] += p[v][j] * col[j * lda + i];
}

// y += a(:, k) x(k, :): a column after the last whole block.
template <int kVectors>
[[gnu::always_inline]] inline void add_column(long rows, const double* __restrict a, long lda,
                                              const double* x, long cols, long k,
                                              double* __restrict y, long ldy) {
  for (int v = 0; v < kVectors; ++v) {
    const double p = x[v * cols + k];
    for (long i = 0; i < rows; ++i) y[v * ldy + i] += p * a[k * lda + i];
  }
}

template <int kVectors, int kLanes = 8>
[[gnu::always_inline]] inline void wide_kernel(long rows, long cols, const double* __restrict a,
                                               long lda, const double* __restrict x,
                                               double* __restrict y, long ldy) {
  zero<kVectors>(rows, y, ldy);
  long k = 0;
  for (; k + kBlock <= cols; k += kBlock)
    add_block<kVectors, kLanes>(rows, a + k * lda, lda, x, cols, k, y, ldy);
  for (; k < cols; ++k) add_column<kVectors>(rows, a, lda, x, cols, k, y, ldy);
}

// y_j = sum_i a_ij x_i for the kColumns columns from j of the rows x cols matrix a (a^T x): against
// one load of x, each sum in 4-double vectors (one AVX2 register) over the rows, the last
// rows % 4 added after. Each column is summed alone, so the bits do not depend on how the
// columns are grouped or shared out.
template <int kColumns>
[[gnu::always_inline]] inline void dot_columns(long rows, const double* __restrict a,
                                               const double* __restrict x, long j,
                                               double* __restrict y) {
  typedef double Lanes __attribute__((vector_size(32)));
  const long body = rows - rows % 4;
  Lanes s[kColumns];
  for (int c = 0; c < kColumns; ++c) s[c] = Lanes{0.0, 0.0, 0.0, 0.0};
  for (long i = 0; i < body; i += 4) {
    Lanes v;
    std::memcpy(&v, x + i, sizeof v);
    for (int c = 0; c < kColumns; ++c) {
      Lanes column;
      std::memcpy(&column, a + (j + c) * rows + i, sizeof column);
      s[c] += column * v;
    }
  }
  for (int c = 0; c < kColumns; ++c) {
    double lanes[4];
    std::memcpy(lanes, &s[c], sizeof lanes);
    double t = (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
    for (long i = body; i < rows; ++i) t += a[(j + c) * rows + i] * x[i];
    y[j + c] = t;
  }
}

// t = a^T g and y = a x in one pass over a, x being written on the way: per chunk of kChunk
// columns (whole blocks of 8; 64 columns of 1,038 rows are 530 kB, within a core's L2 cache),
// their sums t, then fill(context, k, end) (x's rows k .. end - 1 from t's), then the chunk's
// part of y while its columns are still in the cache. The sums read the chunk from L3 (a^T g
// alone 102 us at n = 1,040, the pair 156, one pass 246), but prefetching the next chunk into L2
// during this one's part of y (one prefetch per line read) made the pass slower: 336 to 348
// against 276 us (a standalone copy, chunks of 16 to 64, medians of 15).
constexpr long kChunk = 64;

template <int kVectors, int kLanes>
[[gnu::always_inline]] inline void transposed_then(long rows, long cols, const double* a,
                                                   const double* g, double* t, ProjectionFill fill,
                                                   void* context, const double* x, double* y) {
  zero<kVectors>(rows, y, rows);
  const long whole = cols - cols % kBlock;
  for (long k = 0; k < whole; k += kChunk) {
    const long end = std::min(k + kChunk, whole);
    for (long b = k; b < end; b += kBlock) dot_columns<kBlock>(rows, a, g, b, t);
    fill(context, k, end);
    for (long b = k; b < end; b += kBlock)
      add_block<kVectors, kLanes>(rows, a + b * rows, rows, x, cols, b, y, rows);
  }
  if (whole == cols) return;
  for (long k = whole; k < cols; ++k) dot_columns<1>(rows, a, g, k, t);
  fill(context, whole, cols);
  for (long k = whole; k < cols; ++k) add_column<kVectors>(rows, a, rows, x, cols, k, y, rows);
}

// Clones chosen by the instruction sets the CPU has, not by its model: a clone "arch=haswell" is
// taken only on an Intel Haswell or later (GCC's resolver asks __builtin_cpu_is), so an AMD EPYC
// with AVX2 ran the SSE2 clone: the pair at n = 1,038 took 745 us there against 285 us for AVX2.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && \
    !defined(BEAMRAIL_NO_MULTIVERSION)
#define BEAMRAIL_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#define BEAMRAIL_AVX512 __attribute__((target("avx512f")))
// The environment variable BEAMRAIL_PRODUCTS_WITHOUT_AVX512 (any value) takes the kernels of a
// machine without AVX-512 on one that has it (the kernels in 4 lanes): the tests
// run both wherever they run.
bool has_avx512() {
  static const bool avx512 =
      __builtin_cpu_supports("avx512f") && !std::getenv("BEAMRAIL_PRODUCTS_WITHOUT_AVX512");
  return avx512;
}
#else
#define BEAMRAIL_CLONES
#define BEAMRAIL_AVX512
bool has_avx512() { return false; }
#endif

// The pair in 8 lanes where the CPU has AVX-512 (one register, fused multiply-adds: 4 lanes there
// were multiplications and additions), 4 lanes else. Measured on an AVX-512 machine (AMD EPYC), a
// standalone copy of both, medians of 15 runs of 20, interleaved, three times: n = 1,038 158, 144
// and 162 us against 214, 164 and 167 us; n = 600 49 against 60 us. The tower's run:
// docs/transient_measurements.md "One pass over Phi per stage".
BEAMRAIL_AVX512 void pair_kernel_avx512(long rows, long cols, const double* a, long lda,
                                        const double* x, double* y, long ldy) {
  wide_kernel<2, 8>(rows, cols, a, lda, x, y, ldy);
}

BEAMRAIL_CLONES void pair_kernel_avx2(long rows, long cols, const double* a, long lda,
                                      const double* x, double* y, long ldy) {
  wide_kernel<2, 4>(rows, cols, a, lda, x, y, ldy);
}

void pair_kernel(long rows, long cols, const double* a, long lda, const double* x, double* y,
                 long ldy) {
  (has_avx512() ? pair_kernel_avx512 : pair_kernel_avx2)(rows, cols, a, lda, x, y, ldy);
}

// Three pairs in one pass: in 8 lanes where the CPU has AVX-512, in 4 else.
BEAMRAIL_AVX512 void six_kernel_avx512(long rows, long cols, const double* a, long lda,
                                       const double* x, double* y, long ldy) {
  wide_kernel<6, 8>(rows, cols, a, lda, x, y, ldy);
}

BEAMRAIL_CLONES void six_kernel_avx2(long rows, long cols, const double* a, long lda,
                                     const double* x, double* y, long ldy) {
  wide_kernel<6, 4>(rows, cols, a, lda, x, y, ldy);
}

void six_kernel(long rows, long cols, const double* a, long lda, const double* x, double* y,
                long ldy) {
  (has_avx512() ? six_kernel_avx512 : six_kernel_avx2)(rows, cols, a, lda, x, y, ldy);
}

BEAMRAIL_CLONES void vector_kernel(long rows, long cols, const double* a, long lda, const double* x,
                                   double* y, long ldy) {
  wide_kernel<1, 4>(rows, cols, a, lda, x, y, ldy);
}

// a^T x for the columns [begin, end): eight at a time. Measured on an AVX2 machine (AMD EPYC)
// against Eigen's a.transpose() * x (SSE2 as this library is compiled): n = 1,038 164 against
// 201 us, n = 240 8.2 against 11.5 us, 6,000 x 95 88 against 111 us.
BEAMRAIL_CLONES void transposed_kernel(long rows, long begin, long end, const double* a,
                                       const double* x, double* y) {
  long j = begin;
  for (; j + kBlock <= end; j += kBlock) dot_columns<kBlock>(rows, a, x, j, y);
  for (; j < end; ++j) dot_columns<1>(rows, a, x, j, y);
}

BEAMRAIL_AVX512 void transposed_then_pair_avx512(long rows, long cols, const double* a,
                                                 const double* g, double* t, ProjectionFill fill,
                                                 void* context, const double* x, double* y) {
  transposed_then<2, 8>(rows, cols, a, g, t, fill, context, x, y);
}

BEAMRAIL_CLONES void transposed_then_pair_avx2(long rows, long cols, const double* a,
                                               const double* g, double* t, ProjectionFill fill,
                                               void* context, const double* x, double* y) {
  transposed_then<2, 4>(rows, cols, a, g, t, fill, context, x, y);
}

void transposed_then_pair_kernel(long rows, long cols, const double* a, const double* g, double* t,
                                 ProjectionFill fill, void* context, const double* x, double* y) {
  (has_avx512() ? transposed_then_pair_avx512 : transposed_then_pair_avx2)(rows, cols, a, g, t,
                                                                           fill, context, x, y);
}

BEAMRAIL_AVX512 void transposed_then_six_avx512(long rows, long cols, const double* a,
                                                const double* g, double* t, ProjectionFill fill,
                                                void* context, const double* x, double* y) {
  transposed_then<6, 8>(rows, cols, a, g, t, fill, context, x, y);
}

BEAMRAIL_CLONES void transposed_then_six_avx2(long rows, long cols, const double* a,
                                              const double* g, double* t, ProjectionFill fill,
                                              void* context, const double* x, double* y) {
  transposed_then<6, 4>(rows, cols, a, g, t, fill, context, x, y);
}

void transposed_then_six_kernel(long rows, long cols, const double* a, const double* g, double* t,
                                ProjectionFill fill, void* context, const double* x, double* y) {
  (has_avx512() ? transposed_then_six_avx512 : transposed_then_six_avx2)(rows, cols, a, g, t, fill,
                                                                         context, x, y);
}

using Kernel = void (*)(long, long, const double*, long, const double*, double*, long);

// The product in row blocks, one per thread, where the matrix is large enough for the threads
// to pay off and the calling thread's budget has more than one (threads_for).
void in_row_blocks(Kernel kernel, const Eigen::MatrixXd& a, const double* x, double* y) {
  const long rows = a.rows(), cols = a.cols();
  const int threads = threads_for(rows, cols, rows);
  if (threads <= 1) {
    kernel(rows, cols, a.data(), rows, x, y, rows);
    return;
  }
#ifdef _OPENMP
#pragma omp parallel num_threads(threads)
  {
    const long n = omp_get_num_threads(), id = omp_get_thread_num();
    if (id == 0) count_team(n);
    // Blocks of a multiple of 8 rows (the kernels' vector width): their loads stay aligned as
    // on one thread.
    const long block = (rows / n + 7) / 8 * 8;
    const long begin = std::min(rows, id * block);
    const long end = id + 1 == n ? rows : std::min(rows, begin + block);
    if (end > begin) kernel(end - begin, cols, a.data() + begin, rows, x, y + begin, rows);
  }
#endif
}

}  // namespace

ProductThreads::ProductThreads(int threads) : previous_(product_thread_budget) {
  product_thread_budget = std::max(1, threads);
}

ProductThreads::~ProductThreads() { product_thread_budget = previous_; }

int product_threads() { return product_thread_budget; }

void multiply_pair(const Eigen::MatrixXd& a, const double* x, double* y) {
  in_row_blocks(pair_kernel, a, x, y);
}

bool products_in_avx512() { return has_avx512(); }

void multiply_three_pairs(const Eigen::MatrixXd& a, const double* x, double* y) {
  in_row_blocks(six_kernel, a, x, y);
}

void multiply_vector(const Eigen::MatrixXd& a, const double* x, double* y) {
  in_row_blocks(vector_kernel, a, x, y);
}

void multiply_transposed(const Eigen::MatrixXd& a, const double* x, double* y) {
  const long rows = a.rows(), cols = a.cols();
  const int threads = threads_for(rows, cols, cols);
  if (threads <= 1) {
    transposed_kernel(rows, 0, cols, a.data(), x, y);
    return;
  }
#ifdef _OPENMP
#pragma omp parallel num_threads(threads)
  {
    const long n = omp_get_num_threads(), id = omp_get_thread_num();
    if (id == 0) count_team(n);
    const long block = ((cols + n - 1) / n + 7) / 8 * 8;  // whole groups of 8 columns
    const long begin = std::min(cols, id * block);
    const long end = id + 1 == n ? cols : std::min(cols, begin + block);
    if (end > begin) transposed_kernel(rows, begin, end, a.data(), x, y);
  }
#endif
}

void multiply_transposed_then(const Eigen::MatrixXd& a, const double* g, double* t,
                              ProjectionFill fill, void* context, int vectors, const double* x,
                              double* y) {
  const long rows = a.rows(), cols = a.cols();
  if (threads_for(rows, cols, std::max(rows, cols)) > 1) {
    // Threads share a^T g by columns and a x by rows: two passes, each shared.
    multiply_transposed(a, g, t);
    fill(context, 0, cols);
    if (vectors == 2)
      multiply_pair(a, x, y);
    else
      multiply_three_pairs(a, x, y);
    return;
  }
  if (vectors == 2)
    transposed_then_pair_kernel(rows, cols, a.data(), g, t, fill, context, x, y);
  else
    transposed_then_six_kernel(rows, cols, a.data(), g, t, fill, context, x, y);
}

long products_on_threads() { return products_shared.load(); }

int largest_product_team() { return largest_team.load(); }

}  // namespace beamrail
