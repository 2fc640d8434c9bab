#include "core/analysis/dense_product.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>

namespace beamrail {
namespace {

// Every kernel (one, two and six right-hand sides) on `a` against Eigen's product, each entry
// relative to sum_k |a_ik x_k| (the rounding scale of a dot product); the columns of x differ in
// scale by up to 1e5, which must not mix. Returns the worst difference.
double worst_difference(const Eigen::MatrixXd& a) {
  const Eigen::Index rows = a.rows(), cols = a.cols();
  Eigen::MatrixXd x = Eigen::MatrixXd::Random(cols, 6);
  for (int c = 0; c < 6; ++c) x.col(c) *= std::pow(10.0, c);
  const Eigen::MatrixXd exact = a * x;
  const Eigen::MatrixXd scale = a.cwiseAbs() * x.cwiseAbs();
  Eigen::MatrixXd pair(rows, 2), six(rows, 6);
  Eigen::VectorXd one(rows), transposed(cols);
  multiply_pair(a, x.data(), pair.data());
  multiply_vector(a, x.col(1).data(), one.data());
  multiply_three_pairs(a, x.data(), six.data());
  // a^T u for u = the first column of a x (rows long).
  const Eigen::VectorXd u = exact.col(0) / exact.col(0).cwiseAbs().maxCoeff();
  multiply_transposed(a, u.data(), transposed.data());
  const Eigen::VectorXd transposed_exact = a.transpose() * u;
  const Eigen::VectorXd transposed_scale = a.cwiseAbs().transpose() * u.cwiseAbs();
  double worst = 0.0;
  const double bound = 4 * cols * 1.2e-16;
  auto check = [&](double value, Eigen::Index i, int c, const char* kernel) {
    const double e = std::abs(value - exact(i, c)) / scale(i, c);
    worst = std::max(worst, e);
    EXPECT_LT(e, bound) << rows << " x " << cols << " row " << i << " column " << c << " ("
                        << kernel << ")";
  };
  for (Eigen::Index i = 0; i < rows; ++i) {
    for (int c = 0; c < 2; ++c) check(pair(i, c), i, c, "pair");
    check(one(i), i, 1, "vector");
    for (int c = 0; c < 6; ++c) check(six(i, c), i, c, "three pairs");
  }
  for (Eigen::Index j = 0; j < cols; ++j) {
    const double e = std::abs(transposed(j) - transposed_exact(j)) / transposed_scale(j);
    worst = std::max(worst, e);
    EXPECT_LT(e, 4 * rows * 1.2e-16) << rows << " x " << cols << " column " << j << " (transposed)";
  }
  return worst;
}

TEST(DenseProduct, MatchesEigenAtEverySizeAroundTheBlocking) {
  // The kernels work on 8 columns and 4 or 8 rows at a time and leave
  // remainders; sizes around multiples of 8 and the modal integrator's sizes (6 per body).
  double worst = 0.0;
  for (int n : {1, 2, 5, 7, 8, 9, 15, 16, 17, 60, 240, 601})
    worst = std::max(worst, worst_difference(Eigen::MatrixXd::Random(n, n)));
  std::printf("dense products vs Eigen: worst difference %.2e of the rounding scale\n", worst);
}

TEST(DenseProduct, RectangularMatchesEigen) {
  // A band's basis (n x m, m < n) and other shapes around the blocking of 8.
  double worst = 0.0;
  for (auto [rows, cols] : {std::pair{1, 9},
                            {9, 1},
                            {7, 3},
                            {3, 7},
                            {6, 17},
                            {17, 6},
                            {600, 95},
                            {95, 600},
                            {8, 8},
                            {16, 7}})
    worst = std::max(worst, worst_difference(Eigen::MatrixXd::Random(rows, cols)));
  std::printf("rectangular products vs Eigen: worst difference %.2e of the rounding scale\n",
              worst);
}

// With a budget of threads (ProductThreads) the products above kParallelProductSize entries are
// shared out in blocks of rows (of columns for a^T x), at most one thread per 64 of them, and
// every entry is summed in the same order: the same bits as on one thread, for 2 and 3 threads
// (3 leaves uneven blocks), on the braced tower's square basis, at the threshold, and on a
// band's tall basis (6000 x 95: its rows shared, its transposed product on one thread, 95
// columns) and its transpose's shape (95 x 6000: the transposed product shared). That the
// threads ran is counted (products_on_threads).
TEST(DenseProduct, ThreadsGiveTheSameBits) {
  struct Shape {
    int rows, cols;
    bool rows_shared, columns_shared;
  };
  for (const Shape& shape : {Shape{1038, 1038, true, true}, Shape{363, 362, true, true},
                             Shape{6000, 95, true, false}, Shape{95, 6000, false, true}}) {
    const int rows = shape.rows, cols = shape.cols;
    ASSERT_GE(static_cast<long>(rows) * cols, kParallelProductSize);
    const Eigen::MatrixXd a = Eigen::MatrixXd::Random(rows, cols);
    const Eigen::MatrixXd x = Eigen::MatrixXd::Random(cols, 6);
    const Eigen::VectorXd u = Eigen::VectorXd::Random(rows);
    struct Products {
      Eigen::MatrixXd pair, six;
      Eigen::VectorXd one, transposed;
      long shared = 0;  // products that ran on more than one thread
    };
    auto products = [&](int threads) {
      const ProductThreads budget(threads);
      EXPECT_EQ(product_threads(), threads);
      Products p{Eigen::MatrixXd(rows, 2), Eigen::MatrixXd(rows, 6), Eigen::VectorXd(rows),
                 Eigen::VectorXd(cols)};
      const long before = products_on_threads();
      multiply_pair(a, x.data(), p.pair.data());
      multiply_three_pairs(a, x.data(), p.six.data());
      multiply_vector(a, x.data(), p.one.data());
      multiply_transposed(a, u.data(), p.transposed.data());
      p.shared = products_on_threads() - before;
      return p;
    };
    const Products serial = products(1);
    EXPECT_EQ(serial.shared, 0);
    EXPECT_LT((serial.six - a * x).cwiseAbs().maxCoeff(), 1e-12 * cols);
    for (int threads : {2, 3}) {
      const Products shared = products(threads);
      const std::string label = std::to_string(rows) + " x " + std::to_string(cols) + ", " +
                                std::to_string(threads) + " threads";
      // pair, vector and the three pairs (one product) by rows.
      EXPECT_EQ(shared.shared, 3 * shape.rows_shared + shape.columns_shared) << label;
      EXPECT_TRUE(shared.pair == serial.pair) << label << " (pair)";
      EXPECT_TRUE(shared.six == serial.six) << label << " (three pairs)";
      EXPECT_TRUE(shared.one == serial.one) << label << " (vector)";
      EXPECT_TRUE(shared.transposed == serial.transposed) << label << " (transposed)";
    }
  }
  EXPECT_EQ(product_threads(), 1);
}

// multiply_transposed_then: t = a^T g, then y = a x with x's rows made from t's (here x(k, v) =
// (v + 1) t_k + c_kv, as a modal stage's state is its projected forcing times the modes'
// coefficients plus what is known before), in one pass on one thread and in two shared passes
// with threads: the same bits as multiply_transposed, then multiply_pair or multiply_three_pairs
// given that x, at sizes around the blocking of 8, on a band's tall basis and the tower's square
// one. The fill is asked for every row once, in order.
struct Fill {
  const double* t;
  const Eigen::MatrixXd* c;
  Eigen::MatrixXd* x;
  long next = 0;  // the first row not yet filled
  bool in_order = true;
};

void fill_rows(void* context, long begin, long end) {
  Fill& f = *static_cast<Fill*>(context);
  if (begin != f.next) f.in_order = false;
  f.next = end;
  for (long k = begin; k < end; ++k)
    for (Eigen::Index v = 0; v < f.x->cols(); ++v) (*f.x)(k, v) = (v + 1.0) * f.t[k] + (*f.c)(k, v);
}

TEST(DenseProduct, TransposedThenProductGivesTheBitsOfTwoProducts) {
  for (auto [rows, cols] : {std::pair{1, 1},
                            {7, 9},
                            {9, 7},
                            {17, 17},
                            {60, 60},
                            {240, 240},
                            {600, 95},
                            {95, 600},
                            {1038, 1038}})
    for (int vectors : {2, 6})
      for (int threads : {1, 2}) {
        const std::string label = std::to_string(rows) + " x " + std::to_string(cols) + ", " +
                                  std::to_string(vectors) + " vectors, " + std::to_string(threads) +
                                  " threads";
        const Eigen::MatrixXd a = Eigen::MatrixXd::Random(rows, cols);
        const Eigen::VectorXd g = Eigen::VectorXd::Random(rows);
        const Eigen::MatrixXd c = Eigen::MatrixXd::Random(cols, vectors);
        const ProductThreads budget(threads);
        Eigen::VectorXd t(cols);
        Eigen::MatrixXd x(cols, vectors), y(rows, vectors);
        Fill fill{t.data(), &c, &x};
        multiply_transposed_then(a, g.data(), t.data(), fill_rows, &fill, vectors, x.data(),
                                 y.data());
        EXPECT_TRUE(fill.in_order && fill.next == cols) << label;
        // The two products apart, and against Eigen.
        Eigen::VectorXd t2(cols);
        multiply_transposed(a, g.data(), t2.data());
        Eigen::MatrixXd x2(cols, vectors), y2(rows, vectors);
        Fill fill2{t2.data(), &c, &x2};
        fill_rows(&fill2, 0, cols);
        if (vectors == 2)
          multiply_pair(a, x2.data(), y2.data());
        else
          multiply_three_pairs(a, x2.data(), y2.data());
        EXPECT_TRUE(t == t2) << label << " (a^T g)";
        EXPECT_TRUE(x == x2) << label << " (x)";
        EXPECT_TRUE(y == y2) << label << " (a x)";
        EXPECT_LT((t - a.transpose() * g).cwiseAbs().maxCoeff(), 1e-14 * rows) << label;
        EXPECT_LT((y - a * x).cwiseAbs().maxCoeff(), 1e-14 * rows * cols) << label;
      }
}

// Without BEAMRAIL_PRODUCTS_WITHOUT_AVX512 the products run in AVX-512's 8 lanes where the CPU
// has it; with it (the test dense_product_test.KernelsWithoutAvx512 of tests/CMakeLists.txt runs
// this program so) in 4 lanes, as on a machine without AVX-512.
TEST(DenseProduct, TheEnvironmentTakesTheKernelsWithoutAvx512) {
  const bool without = std::getenv("BEAMRAIL_PRODUCTS_WITHOUT_AVX512") != nullptr;
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && \
    !defined(BEAMRAIL_NO_MULTIVERSION)
  const bool avx512 = __builtin_cpu_supports("avx512f");
#else
  const bool avx512 = false;
#endif
  std::printf("AVX-512 %s, kernels %s\n", avx512 ? "present" : "absent",
              products_in_avx512() ? "with it" : "without it");
  EXPECT_EQ(products_in_avx512(), avx512 && !without);
}

}  // namespace
}  // namespace beamrail
