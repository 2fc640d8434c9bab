// Dense symmetric eigenproblems, every eigenpair: A x = lambda x and A x = lambda B x (B
// symmetric positive definite, vectors B-normalized), eigenvalues ascending.
//
// From kLapackEigenFrom rows on (below kLapackEigenBelow, LAPACK's int sizes) they go to
// LAPACK's divide-and-conquer drivers (dsyevd, dsygvd, from the serial OpenBLAS), below to
// Eigen's QL iteration. The reference cantilever's
// K and M (tests/benchmarks/dense_eigen_benchmark, medians of 3, AVX2 machine), Eigen against
// LAPACK: 1,038 dof 1,136 against 300 ms, 600 dof 228 against 62 ms, 240 dof 16.7 against
// 6.4 ms, 102 dof 1.39 against 0.89 ms, 60 dof 0.32 against 0.53 ms.
// The calls to LAPACK are serialized by a lock: the serial OpenBLAS is not documented as safe
// for concurrent calls, and a batch evaluates designs on several threads. When LAPACK reports
// a failure (B not positive definite, no convergence) the automatic choice tries Eigen's solver
// instead, as before these drivers, so that its callers keep their own checks; kLapack alone
// then returns false.
#pragma once

#include <Eigen/Dense>

namespace beamrail {

enum class DenseEigenDriver { kAutomatic, kEigen, kLapack };

inline constexpr Eigen::Index kLapackEigenFrom = 100;
// LAPACK's sizes are ints: dsygvd's workspace, 1 + 6 n + 2 n^2, passes INT_MAX from n = 32,767.
// From there on, kAutomatic stays with Eigen and kLapack returns false.
inline constexpr Eigen::Index kLapackEigenBelow = 32767;

// Whether kAutomatic takes LAPACK for a problem of `rows` rows (kLapackEigenFrom <= rows <
// kLapackEigenBelow): the one place of that choice, for callers with a LAPACK-only route.
bool lapack_eigen_automatic(Eigen::Index rows);

// False when the solver failed (non-finite input, no convergence; kLapack: also B not positive
// definite, or kLapackEigenBelow rows or more).
bool symmetric_eigen(const Eigen::MatrixXd& a, Eigen::VectorXd& values, Eigen::MatrixXd& vectors,
                     DenseEigenDriver driver = DenseEigenDriver::kAutomatic);

bool generalized_symmetric_eigen(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
                                 Eigen::VectorXd& values, Eigen::MatrixXd& vectors,
                                 DenseEigenDriver driver = DenseEigenDriver::kAutomatic);

}  // namespace beamrail
