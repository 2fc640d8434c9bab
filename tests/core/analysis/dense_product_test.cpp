#include "core/analysis/dense_product.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <utility>

namespace beamrail {
namespace {

TEST(DenseProduct, MatchesEigenAtEverySizeAroundTheBlocking) {
  // The kernel works on 8 columns at a time and leaves a remainder; sizes around multiples of 8
  // and the modal integrator's sizes (6 per body). Each entry against Eigen's product, relative to
  // sum_k |a_ik x_k| (the rounding scale of a dot product).
  double worst = 0.0;
  for (int n : {1, 2, 5, 7, 8, 9, 15, 16, 17, 60, 240, 601}) {
    Eigen::MatrixXd a = Eigen::MatrixXd::Random(n, n);
    Eigen::MatrixXd x = Eigen::MatrixXd::Random(n, 2);
    x.col(1) *= 1e3;  // columns of different scale must not mix
    Eigen::MatrixXd y(n, 2);
    Eigen::VectorXd v(n);
    multiply_pair(a, x.data(), y.data());
    multiply_vector(a, x.col(1).data(), v.data());
    const Eigen::MatrixXd exact = a * x;
    const Eigen::MatrixXd scale = a.cwiseAbs() * x.cwiseAbs();
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 2; ++c) {
        const double e = std::abs(y(i, c) - exact(i, c)) / scale(i, c);
        worst = std::max(worst, e);
        EXPECT_LT(e, 4 * n * 1.2e-16) << "n " << n << " row " << i << " column " << c;
      }
    for (int i = 0; i < n; ++i) {
      const double e = std::abs(v(i) - exact(i, 1)) / scale(i, 1);
      worst = std::max(worst, e);
      EXPECT_LT(e, 4 * n * 1.2e-16) << "n " << n << " row " << i << " (one vector)";
    }
  }
  std::printf("dense products vs Eigen: worst difference %.2e of the rounding scale\n", worst);
}

TEST(DenseProduct, RectangularMatchesEigen) {
  // A band's basis (n x m, m < n) and its transpose (m x n), around the blocking of 8 columns.
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
                            {16, 7}}) {
    const Eigen::MatrixXd a = Eigen::MatrixXd::Random(rows, cols);
    Eigen::MatrixXd x = Eigen::MatrixXd::Random(cols, 2);
    x.col(1) *= 1e3;
    Eigen::MatrixXd y(rows, 2);
    Eigen::VectorXd v(rows);
    multiply_pair(a, x.data(), y.data());
    multiply_vector(a, x.col(1).data(), v.data());
    const Eigen::MatrixXd exact = a * x;
    const Eigen::MatrixXd scale = a.cwiseAbs() * x.cwiseAbs();
    for (int i = 0; i < rows; ++i) {
      for (int c = 0; c < 2; ++c) {
        const double e = std::abs(y(i, c) - exact(i, c)) / scale(i, c);
        worst = std::max(worst, e);
        EXPECT_LT(e, 4 * cols * 1.2e-16) << rows << " x " << cols << " row " << i << " col " << c;
      }
      const double e = std::abs(v(i) - exact(i, 1)) / scale(i, 1);
      worst = std::max(worst, e);
      EXPECT_LT(e, 4 * cols * 1.2e-16) << rows << " x " << cols << " row " << i << " (vector)";
    }
  }
  std::printf("rectangular products vs Eigen: worst difference %.2e of the rounding scale\n",
              worst);
}

}  // namespace
}  // namespace beamrail
