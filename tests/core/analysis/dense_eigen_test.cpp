// The dense symmetric eigensolvers (core/analysis/dense_eigen.hpp): LAPACK's drivers against a
// closed form, against Eigen's solver on a structure's K and M, from two threads at once, and
// the fall-back to Eigen when LAPACK refuses a pencil.
#include "core/analysis/dense_eigen.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <thread>
#include <vector>

#include "core/model/data.hpp"
#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"
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

// K and M of the reference cantilever in 30 segments (180 dof, a spectrum of 9 decades).
void cantilever(Eigen::MatrixXd& k, Eigen::MatrixXd& m) {
  const Model model = testing::scene_from_json(testing::reference_cantilever(30));
  Data data(model);
  std::vector<double> y(static_cast<size_t>(model.n_states));
  initial_state(model, y.data());
  set_state(model, data, y.data());
  compute_wrenches(model, data, 0.0);
  compute_tangent(model, data, 0.0, false);
  const Eigen::MatrixXd s = -Eigen::MatrixXd(stiffness_matrix(model, data));
  k = 0.5 * (s + s.transpose());
  m = Eigen::MatrixXd(mass_matrix(model, data));
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
  // B indefinite: LAPACK's Cholesky of B fails (info > n); Eigen's solver is asked instead, as
  // before these drivers, and both choices return the same.
  const int n = 120;
  Eigen::MatrixXd k, m;
  bar(n, k, m);
  m(n / 2, n / 2) = -1.0;
  Eigen::VectorXd ve, vl;
  Eigen::MatrixXd xe, xl;
  const bool eigen_ok = generalized_symmetric_eigen(k, m, ve, xe, DenseEigenDriver::kEigen);
  const bool lapack_ok = generalized_symmetric_eigen(k, m, vl, xl, DenseEigenDriver::kLapack);
  EXPECT_EQ(eigen_ok, lapack_ok);
  if (eigen_ok && lapack_ok) {
    EXPECT_EQ((ve - vl).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ((xe - xl).cwiseAbs().maxCoeff(), 0.0);
  }
  // Non-finite input: false or Eigen's answer, never LAPACK on NaN.
  k(3, 3) = std::nan("");
  Eigen::VectorXd values;
  Eigen::MatrixXd vectors;
  const bool nan_ok = symmetric_eigen(k, values, vectors, DenseEigenDriver::kLapack);
  EXPECT_TRUE(!nan_ok || !values.allFinite());
}

}  // namespace
}  // namespace beamrail
