#include "core/analysis/dense_product.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
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
  Eigen::VectorXd one(rows), back(cols);
  multiply_pair(a, x.data(), pair.data());
  multiply_vector(a, x.col(1).data(), one.data());
  multiply_three_pairs(a, x.data(), six.data());
  // The transposed product, on a vector of rows entries.
  const Eigen::VectorXd w = 1e3 * Eigen::VectorXd::Random(rows);
  multiply_transposed(a, w.data(), back.data());
  const Eigen::VectorXd back_exact = a.transpose() * w;
  const Eigen::VectorXd back_scale = a.cwiseAbs().transpose() * w.cwiseAbs();
  double worst = 0.0;
  const double bound = 4 * cols * 1.2e-16;
  auto check = [&](double value, Eigen::Index i, int c, const char* kernel) {
    const double e = std::abs(value - exact(i, c)) / scale(i, c);
    worst = std::max(worst, e);
    EXPECT_LT(e, bound) << rows << " x " << cols << " row " << i << " column " << c << " ("
                        << kernel << ")";
  };
  for (Eigen::Index k = 0; k < cols; ++k) {
    const double e = std::abs(back(k) - back_exact(k)) / back_scale(k);
    worst = std::max(worst, e);
    EXPECT_LT(e, 4 * rows * 1.2e-16) << rows << " x " << cols << " column " << k << " (transposed)";
  }
  for (Eigen::Index i = 0; i < rows; ++i) {
    for (int c = 0; c < 2; ++c) check(pair(i, c), i, c, "pair");
    check(one(i), i, 1, "vector");
    for (int c = 0; c < 6; ++c) check(six(i, c), i, c, "three pairs");
  }
  return worst;
}

TEST(DenseProduct, MatchesEigenAtEverySizeAroundTheBlocking) {
  // The kernels work on 8 columns (and the six-vector one on 8 rows) at a time and leave
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

// The products spread over threads in slabs of rows (columns for the transposed one), each entry
// summed by one thread in the same order: the same bits for any number of threads, so a run's
// results do not depend on -j. Sizes above the threshold where a product takes threads, the
// slabs' boundaries not on the blocking of 8 and a band's rectangles.
TEST(DenseProduct, ThreadsGiveTheSameBits) {
  const int before = omp_get_max_threads();
  for (auto [rows, cols] : {std::pair{1038, 1038}, {601, 601}, {1203, 97}, {97, 1203}}) {
    const Eigen::MatrixXd a = Eigen::MatrixXd::Random(rows, cols);
    const Eigen::MatrixXd x = Eigen::MatrixXd::Random(cols, 6);
    const Eigen::VectorXd w = Eigen::VectorXd::Random(rows);
    auto products = [&](int threads) {
      omp_set_num_threads(threads);
      Eigen::MatrixXd out(rows, 9);
      Eigen::VectorXd back(cols);
      multiply_pair(a, x.data(), out.data());
      multiply_vector(a, x.col(2).data(), out.col(2).data());
      multiply_three_pairs(a, x.data(), out.col(3).data());
      multiply_transposed(a, w.data(), back.data());
      return std::pair{out, back};
    };
    const auto one = products(1);
    for (int threads : {2, 3, 8}) {
      const auto many = products(threads);
      EXPECT_TRUE(many.first == one.first)
          << rows << " x " << cols << ", " << threads << " threads";
      EXPECT_TRUE(many.second == one.second)
          << rows << " x " << cols << ", " << threads << " threads (transposed)";
    }
    // And the threaded products are the products (against Eigen, to rounding).
    omp_set_num_threads(2);
    const Eigen::MatrixXd exact = a * x.leftCols<2>();
    EXPECT_LT((one.first.leftCols<2>() - exact).cwiseAbs().maxCoeff(), 1e-12 * cols);
  }
  omp_set_num_threads(before);
}

}  // namespace
}  // namespace beamrail
