// The dense symmetric eigensolvers (core/analysis/dense_eigen.hpp): LAPACK's drivers against a
// closed form, against Eigen's solver on a structure's K and M, from two threads at once, and
// the fall-back to Eigen when LAPACK refuses a pencil.
#include "core/analysis/dense_eigen.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <thread>
#include <vector>

#include "core/analysis/modal_analysis.hpp"
#include "tests/support/pencil.hpp"
#include "tests/support/reference_cantilever.hpp"
#include "tests/support/scenes.hpp"

namespace beamrail {
namespace {

constexpr double kPi = std::numbers::pi;

// A bar of linear finite elements, fixed at both ends: K = (1/h) tridiag(-1, 2, -1), M = (h/6)
// tridiag(1, 4, 1). Both are Toeplitz with the eigenvectors sin(j k pi / (n + 1)), so
// lambda_k = (6 / h^2) (1 - cos t) / (2 + cos t), t = k pi / (n + 1).
void bar(int n, Eigen::MatrixXd& k, Eigen::MatrixXd& m) {
  const double h = 1.0 / (n + 1);
  k = Eigen::MatrixXd::Zero(n, n);
  m = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    k(i, i) = 2.0 / h;
    m(i, i) = 4.0 * h / 6.0;
    if (i + 1 < n) {
      k(i, i + 1) = k(i + 1, i) = -1.0 / h;
      m(i, i + 1) = m(i + 1, i) = h / 6.0;
    }
  }
}

double bar_eigenvalue(int n, int k) {
  const double h = 1.0 / (n + 1), t = k * kPi / (n + 1);
  return 6.0 / (h * h) * (1.0 - std::cos(t)) / (2.0 + std::cos(t));
}

// The largest |A v - lambda B v| / (|A| |v|) and |V^T B V - I| of a solution.
void check_pairs(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const Eigen::VectorXd& values,
                 const Eigen::MatrixXd& vectors, double* residual, double* orthogonality) {
  const Eigen::MatrixXd r = a * vectors - b * vectors * values.asDiagonal();
  *residual = 0.0;
  for (Eigen::Index j = 0; j < r.cols(); ++j)
    *residual = std::max(*residual, r.col(j).norm() / (a.norm() * vectors.col(j).norm()));
  const Eigen::Index n = vectors.cols();
  *orthogonality =
      (vectors.transpose() * b * vectors - Eigen::MatrixXd::Identity(n, n)).cwiseAbs().maxCoeff();
}

TEST(DenseEigen, GeneralizedMatchesTheClosedFormOfABar) {
  for (int n : {40, 150}) {
    Eigen::MatrixXd k, m;
    bar(n, k, m);
    for (DenseEigenDriver driver : {DenseEigenDriver::kEigen, DenseEigenDriver::kLapack}) {
      Eigen::VectorXd values;
      Eigen::MatrixXd vectors;
      ASSERT_TRUE(generalized_symmetric_eigen(k, m, values, vectors, driver));
      double worst = 0.0;
      for (int i = 0; i < n; ++i)
        worst = std::max(worst, std::abs(values(i) / bar_eigenvalue(n, i + 1) - 1.0));
      double residual = 0.0, orthogonality = 0.0;
      check_pairs(k, m, values, vectors, &residual, &orthogonality);
      std::printf(
          "n %d %s: eigenvalues within %.2e of the closed form, residual %.2e, "
          "|V^T M V - I| %.2e\n",
          n, driver == DenseEigenDriver::kLapack ? "LAPACK" : "Eigen", worst, residual,
          orthogonality);
      // The spectrum spans (n + 1)^2 / 2.5: the lowest is resolved to ~eps times that.
      EXPECT_LT(worst, 1e-16 * (n + 1) * (n + 1) * 10.0);
      EXPECT_LT(residual, 1e-14);
      EXPECT_LT(orthogonality, 1e-12);
    }
  }
}

TEST(DenseEigen, StandardMatchesTheClosedFormOfTheSecondDifference) {
  const int n = 130;  // above kLapackEigenFrom: the automatic choice is LAPACK
  ASSERT_GE(n, kLapackEigenFrom);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    a(i, i) = 2.0;
    if (i + 1 < n) a(i, i + 1) = a(i + 1, i) = -1.0;
  }
  Eigen::VectorXd values;
  Eigen::MatrixXd vectors;
  ASSERT_TRUE(symmetric_eigen(a, values, vectors));
  double worst = 0.0;
  for (int i = 0; i < n; ++i)
    worst = std::max(worst, std::abs(values(i) - (2.0 - 2.0 * std::cos((i + 1) * kPi / (n + 1)))));
  double residual = 0.0, orthogonality = 0.0;
  check_pairs(a, Eigen::MatrixXd::Identity(n, n), values, vectors, &residual, &orthogonality);
  std::printf("second difference, n %d: eigenvalues within %.2e, residual %.2e, |V^T V - I| %.2e\n",
              n, worst, residual, orthogonality);
  EXPECT_LT(worst, 1e-13);
  EXPECT_LT(residual, 1e-14);
  EXPECT_LT(orthogonality, 1e-12);
}

// K and M of the reference cantilever in 30 segments (180 dof, a spectrum of 3.5e7).
void cantilever(Eigen::MatrixXd& k, Eigen::MatrixXd& m) {
  const testing::Pencil pencil =
      testing::pencil_at_rest(testing::scene_from_json(testing::reference_cantilever(30)));
  k = pencil.k;
  m = pencil.m;
}

TEST(DenseEigen, LapackAgreesWithEigenOnACantilever) {
  Eigen::MatrixXd k, m;
  cantilever(k, m);
  ASSERT_GE(k.rows(), kLapackEigenFrom);
  Eigen::VectorXd ve, vl;
  Eigen::MatrixXd xe, xl;
  ASSERT_TRUE(generalized_symmetric_eigen(k, m, ve, xe, DenseEigenDriver::kEigen));
  ASSERT_TRUE(generalized_symmetric_eigen(k, m, vl, xl, DenseEigenDriver::kLapack));
  // The direct problem resolves each eigenvalue to ~eps lambda_max.
  const double top = ve.cwiseAbs().maxCoeff();
  const double values = (ve - vl).cwiseAbs().maxCoeff() / top;
  // Vectors up to sign, in the M norm, where the neighbours are 1 % apart (the round section's
  // pairs of equal frequencies have no unique vectors).
  double vectors = 0.0;
  int compared = 0;
  for (Eigen::Index j = 0; j < ve.size(); ++j) {
    const double gap = std::min(j > 0 ? std::abs(ve(j) - ve(j - 1)) : top,
                                j + 1 < ve.size() ? std::abs(ve(j + 1) - ve(j)) : top);
    if (gap < 0.01 * std::abs(ve(j))) continue;
    const double sign = xe.col(j).dot(m * xl.col(j)) < 0.0 ? -1.0 : 1.0;
    const Eigen::VectorXd d = xe.col(j) - sign * xl.col(j);
    vectors = std::max(vectors, std::sqrt(d.dot(m * d)));
    ++compared;
  }
  double residual = 0.0, orthogonality = 0.0;
  check_pairs(k, m, vl, xl, &residual, &orthogonality);
  std::printf(
      "cantilever, %ld dof: eigenvalues within %.2e of lambda_max, %d vectors within "
      "%.2e (M norm), LAPACK's residual %.2e, |V^T M V - I| %.2e\n",
      static_cast<long>(k.rows()), values, compared, vectors, residual, orthogonality);
  EXPECT_LT(values, 1e-13);
  EXPECT_GT(compared, 30);
  EXPECT_LT(vectors, 1e-9);
  EXPECT_LT(residual, 1e-14);
  EXPECT_LT(orthogonality, 1e-11);
}

TEST(DenseEigen, TheInverseProblemKeepsTheLowestModesToTheirOwnAccuracy) {
  // solve_dense_eigenproblem takes the lower half of a wide spectrum from the inverse problem,
  // from 100 dof the pencil (M, K) by LAPACK. Reference: the inverse problem in long double
  // (eps 1e-19) by Eigen, B = L^T K^-1 L with M = L L^T, whose largest eigenvalues are the
  // lowest modes' 1 / w^2 to ~1e-19 of themselves. In double both routes are held near 1e-11
  // by the factorization of K (Eigen's, L^T K^-1 L: 1.07e-11 on the lowest mode; LAPACK's pencil
  // 1.28e-11), against eps lambda_max / lambda_min = 4e-9 for the direct problem.
  Eigen::MatrixXd k, m;
  cantilever(k, m);
  using MatrixL = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
  const MatrixL kl = k.cast<long double>(), ml = m.cast<long double>();
  const Eigen::LLT<MatrixL> mf(ml);
  const MatrixL l = mf.matrixL();
  MatrixL b = l.transpose() * Eigen::LLT<MatrixL>(kl).solve(l);
  b = ((b + b.transpose()) / 2).eval();
  const Eigen::SelfAdjointEigenSolver<MatrixL> inverse(b);
  ASSERT_EQ(inverse.info(), Eigen::Success);
  const Eigen::Index n = k.rows();
  Eigen::VectorXd values;
  Eigen::MatrixXd vectors;
  ASSERT_TRUE(solve_dense_eigenproblem(k, m, values, vectors));
  ASSERT_GT(values(n - 1), 1e6 * values(0));  // the inverse problem is used
  double worst = 0.0, worst_vector = 0.0;
  for (int i = 0; i < 20; ++i) {
    const long double exact = 1.0L / inverse.eigenvalues()(n - 1 - i);
    worst = std::max(worst, static_cast<double>(std::abs(values(i) / exact - 1.0L)));
    // Separated modes only (the square section's pairs have no unique vectors).
    const long double next = 1.0L / inverse.eigenvalues()(n - 2 - i);
    const long double previous = i > 0 ? 1.0L / inverse.eigenvalues()(n - i) : 0.0L;
    if (next - exact < 0.01L * exact || (i > 0 && exact - previous < 0.01L * exact)) continue;
    const Eigen::VectorXd x =
        mf.matrixU().solve(inverse.eigenvectors().col(n - 1 - i)).eval().cast<double>();
    const double sign = x.dot(m * vectors.col(i)) < 0.0 ? -1.0 : 1.0;
    const Eigen::VectorXd d = vectors.col(i) - sign * x;
    worst_vector = std::max(worst_vector, std::sqrt(d.dot(m * d)));
  }
  std::printf(
      "cantilever, %ld dof, spectrum of %.1e: the lowest 20 eigenvalues within %.2e of "
      "the long double inverse problem, their separated vectors within %.2e (M norm)\n",
      static_cast<long>(n), values(n - 1) / values(0), worst, worst_vector);
  EXPECT_LT(worst, 3e-11);
  EXPECT_LT(worst_vector, 1e-9);
}

TEST(DenseEigen, TwoThreadsAtOnceGiveTheSerialResult) {
  Eigen::MatrixXd k, m;
  cantilever(k, m);
  Eigen::VectorXd serial_values;
  Eigen::MatrixXd serial_vectors;
  ASSERT_TRUE(generalized_symmetric_eigen(k, m, serial_values, serial_vectors));
  Eigen::VectorXd values[2];
  Eigen::MatrixXd vectors[2];
  bool ok[2] = {false, false};
  {
    std::thread first([&] {
      for (int r = 0; r < 5; ++r) ok[0] = generalized_symmetric_eigen(k, m, values[0], vectors[0]);
    });
    std::thread second([&] {
      for (int r = 0; r < 5; ++r) ok[1] = generalized_symmetric_eigen(k, m, values[1], vectors[1]);
    });
    first.join();
    second.join();
  }
  for (int i = 0; i < 2; ++i) {
    ASSERT_TRUE(ok[i]);
    EXPECT_EQ((values[i] - serial_values).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ((vectors[i] - serial_vectors).cwiseAbs().maxCoeff(), 0.0);
  }
}

TEST(DenseEigen, APencilLapackRefusesGoesToEigen) {
  // B indefinite: LAPACK's Cholesky of B fails (info > n). Asked for LAPACK alone, false; the
  // automatic choice asks Eigen's solver instead, as before these drivers.
  const int n = 120;
  ASSERT_GE(n, kLapackEigenFrom);
  Eigen::MatrixXd k, m;
  bar(n, k, m);
  m(n / 2, n / 2) = -1.0;
  Eigen::VectorXd ve, va, vl;
  Eigen::MatrixXd xe, xa, xl;
  EXPECT_FALSE(generalized_symmetric_eigen(k, m, vl, xl, DenseEigenDriver::kLapack));
  const bool eigen_ok = generalized_symmetric_eigen(k, m, ve, xe, DenseEigenDriver::kEigen);
  const bool automatic_ok = generalized_symmetric_eigen(k, m, va, xa);
  EXPECT_EQ(eigen_ok, automatic_ok);
  if (eigen_ok && automatic_ok) {
    EXPECT_EQ((ve - va).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ((xe - xa).cwiseAbs().maxCoeff(), 0.0);
  }
  // Non-finite input never reaches LAPACK.
  k(3, 3) = std::nan("");
  Eigen::VectorXd values;
  Eigen::MatrixXd vectors;
  EXPECT_FALSE(symmetric_eigen(k, values, vectors, DenseEigenDriver::kLapack));
  EXPECT_FALSE(generalized_symmetric_eigen(k, m, values, vectors, DenseEigenDriver::kLapack));
}

TEST(DenseEigen, LapacksIntSizesBoundTheChoice) {
  // The automatic choice takes LAPACK from kLapackEigenFrom rows up to LAPACK's int limit, where
  // dsygvd's workspace 1 + 6 n + 2 n^2 first passes INT_MAX.
  const auto workspace = [](long long n) { return 1 + 6 * n + 2 * n * n; };
  EXPECT_LE(workspace(kLapackEigenBelow - 1), std::numeric_limits<int>::max());
  EXPECT_GT(workspace(kLapackEigenBelow), std::numeric_limits<int>::max());
  EXPECT_FALSE(lapack_eigen_automatic(kLapackEigenFrom - 1));
  EXPECT_TRUE(lapack_eigen_automatic(kLapackEigenFrom));
  EXPECT_TRUE(lapack_eigen_automatic(kLapackEigenBelow - 1));
  EXPECT_FALSE(lapack_eigen_automatic(kLapackEigenBelow));
  // Asked for LAPACK alone at the limit, false before the data is looked at (so without the 8 GiB
  // of a square matrix: these have no columns); not Eigen's answer in LAPACK's place, which the
  // inverse problem's LAPACK-only route (modal_analysis.cpp) relies on.
  const Eigen::MatrixXd huge(kLapackEigenBelow, 0);
  Eigen::VectorXd values;
  Eigen::MatrixXd vectors;
  EXPECT_FALSE(symmetric_eigen(huge, values, vectors, DenseEigenDriver::kLapack));
  EXPECT_FALSE(generalized_symmetric_eigen(huge, huge, values, vectors, DenseEigenDriver::kLapack));
}

}  // namespace
}  // namespace beamrail
