// Products of a dense matrix with one, two or six vectors: the modal integrator's changes of basis,
// five passes over the matrix per step (every mode: each a^T x with the a x that follows it) to
// twenty (a band's quasi-static iteration), on matrices up to 1200 x 1200 (every mode) or n x m (a
// band of m modes of n degrees of freedom, 6000 x 95 and more).
//
// Eigen's product of a dynamic matrix with an n x 2 block takes its matrix-matrix path, which
// repacks the big factor on every call; as two matrix-vector products it is twice as fast, and
// this kernel (both columns in one pass over the matrix, eight matrix columns at a time, compiled
// for several instruction sets with the one the CPU has chosen at load time) twice again:
// measured at n = 240 on the reference machine, 28 us, 15 us and 7.1 us.
//
// Threads: a matrix of at least kParallelProductSize entries is multiplied in blocks of rows (of
// columns for a^T x), one per thread of the calling thread's budget (ProductThreads; 1 unless a
// caller sets it: a single run gets the cores a batch of designs would use, a run inside a batch
// keeps 1), at most one per 64 rows (columns) shared. Each entry is summed in the same order
// whatever the threads: the results are the same to the bit.
#pragma once

#include <Eigen/Core>

namespace beamrail {

// Matrices with at least this many entries are multiplied by the threads of the budget.
inline constexpr long kParallelProductSize = 1L << 17;

// The calling thread's budget of threads for the products while the object lives (at least 1);
// the budget before it is restored after.
class ProductThreads {
 public:
  explicit ProductThreads(int threads);
  ~ProductThreads();
  ProductThreads(const ProductThreads&) = delete;
  ProductThreads& operator=(const ProductThreads&) = delete;

 private:
  int previous_;
};

// The calling thread's budget.
int product_threads();

// How many products (of any thread) have run on more than one thread since the program started.
long products_on_threads();

// The most threads one product has run on since the program started (1 when none was shared).
int largest_product_team();

// y = a x for the column-major arrays x (a.cols() x 2) and y (a.rows() x 2): two vectors side by
// side.
void multiply_pair(const Eigen::MatrixXd& a, const double* x, double* y);

// y = a x for x (a.cols() x 6) and y (a.rows() x 6), column-major: three pairs (a trial step's
// new state and its two error estimates) in one pass over a.
void multiply_three_pairs(const Eigen::MatrixXd& a, const double* x, double* y);

// Whether the products run their kernels in AVX-512's 8 lanes (else in AVX2's 4, or the
// compiler's default; BEAMRAIL_PRODUCTS_WITHOUT_AVX512 takes those where the CPU has AVX-512).
bool products_in_avx512();

// y = a x for the vectors x (length a.cols()) and y (length a.rows()).
void multiply_vector(const Eigen::MatrixXd& a, const double* x, double* y);

// y = a^T x for the vectors x (length a.rows()) and y (length a.cols()).
void multiply_transposed(const Eigen::MatrixXd& a, const double* x, double* y);

// Writes the rows [begin, end) of each column of a product's right-hand side x from the entries
// [begin, end) of t = a^T g (multiply_transposed_then).
using ProjectionFill = void (*)(void* context, long begin, long end);

// t = a^T g (t: a.cols()), then y = a x for x (a.cols() x vectors, vectors 2 or 6) whose rows
// fill writes from t's same rows: a change of basis whose result sets the next one mode by mode,
// as a stage of the modal method projects its forcing and builds the next stage. On one thread
// in one pass over a, in chunks of columns: their sums, their rows of x (fill, called in order,
// once per row), their part of y while the chunk is in the cache; with threads two passes, each
// shared. The results are those of multiply_transposed, then multiply_pair or
// multiply_three_pairs, to the bit.
void multiply_transposed_then(const Eigen::MatrixXd& a, const double* g, double* t,
                              ProjectionFill fill, void* context, int vectors, const double* x,
                              double* y);

}  // namespace beamrail
