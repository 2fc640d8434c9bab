#include "core/analysis/dense_product.hpp"

#include <gtest/gtest.h>

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
  Eigen::VectorXd one(rows);
  multiply_pair(a, x.data(), pair.data());
  multiply_vector(a, x.col(1).data(), one.data());
  multiply_three_pairs(a, x.data(), six.data());
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

}  // namespace
}  // namespace beamrail
