#include "core/analysis/dense_eigen.hpp"

#include <cstddef>
#include <mutex>
#include <vector>

// LAPACK's Fortran interface (the hidden lengths of the character arguments last, as gfortran
// passes them).
extern "C" {
void dsyevd_(const char* jobz, const char* uplo, const int* n, double* a, const int* lda, double* w,
             double* work, const int* lwork, int* iwork, const int* liwork, int* info,
             std::size_t jobz_length, std::size_t uplo_length);
void dsygvd_(const int* itype, const char* jobz, const char* uplo, const int* n, double* a,
             const int* lda, double* b, const int* ldb, double* w, double* work, const int* lwork,
             int* iwork, const int* liwork, int* info, std::size_t jobz_length,
             std::size_t uplo_length);
}

namespace beamrail {
namespace {

std::mutex& lapack_lock() {
  static std::mutex lock;
  return lock;
}

bool try_lapack(Eigen::Index n, DenseEigenDriver driver) {
  return driver == DenseEigenDriver::kLapack ||
         (driver == DenseEigenDriver::kAutomatic && lapack_eigen_automatic(n));
}

// One LAPACK driver call: a workspace query, then the call. `call(work, lwork, iwork, liwork)`
// returns info.
template <class Call>
bool run_with_workspace(Call call) {
  double work_size = 0.0;
  int iwork_size = 0;
  const int query = -1;
  if (call(&work_size, &query, &iwork_size, &query) != 0) return false;
  const int lwork = static_cast<int>(work_size);
  const int liwork = iwork_size;
  std::vector<double> work(static_cast<std::size_t>(lwork));
  std::vector<int> iwork(static_cast<std::size_t>(liwork));
  return call(work.data(), &lwork, iwork.data(), &liwork) == 0;
}

bool lapack_symmetric(const Eigen::MatrixXd& a, Eigen::VectorXd& values, Eigen::MatrixXd& vectors) {
  if (a.rows() >= kLapackEigenBelow) return false;  // its sizes are ints
  const int n = static_cast<int>(a.rows());
  vectors = a;
  values.resize(n);
  const std::lock_guard<std::mutex> hold(lapack_lock());
  return run_with_workspace([&](double* work, const int* lwork, int* iwork, const int* liwork) {
    int info = 0;
    dsyevd_("V", "L", &n, vectors.data(), &n, values.data(), work, lwork, iwork, liwork, &info, 1,
            1);
    return info;
  });
}

bool lapack_generalized(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, Eigen::VectorXd& values,
                        Eigen::MatrixXd& vectors) {
  if (a.rows() >= kLapackEigenBelow) return false;  // its sizes are ints
  const int n = static_cast<int>(a.rows());
  const int itype = 1;  // A x = lambda B x
  vectors = a;
  Eigen::MatrixXd factor = b;
  values.resize(n);
  const std::lock_guard<std::mutex> hold(lapack_lock());
  return run_with_workspace([&](double* work, const int* lwork, int* iwork, const int* liwork) {
    int info = 0;
    dsygvd_(&itype, "V", "L", &n, vectors.data(), &n, factor.data(), &n, values.data(), work, lwork,
            iwork, liwork, &info, 1, 1);
    return info;
  });
}

}  // namespace

bool lapack_eigen_automatic(Eigen::Index rows) {
  return rows >= kLapackEigenFrom && rows < kLapackEigenBelow;
}

bool symmetric_eigen(const Eigen::MatrixXd& a, Eigen::VectorXd& values, Eigen::MatrixXd& vectors,
                     DenseEigenDriver driver) {
  if (try_lapack(a.rows(), driver)) {
    if (a.allFinite() && lapack_symmetric(a, values, vectors)) return true;
    if (driver == DenseEigenDriver::kLapack) return false;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(a);
  if (eig.info() != Eigen::Success) return false;
  values = eig.eigenvalues();
  vectors = eig.eigenvectors();
  return true;
}

bool generalized_symmetric_eigen(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
                                 Eigen::VectorXd& values, Eigen::MatrixXd& vectors,
                                 DenseEigenDriver driver) {
  if (try_lapack(a.rows(), driver)) {
    if (a.allFinite() && b.allFinite() && lapack_generalized(a, b, values, vectors)) return true;
    if (driver == DenseEigenDriver::kLapack) return false;
  }
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(a, b);
  if (eig.info() != Eigen::Success) return false;
  values = eig.eigenvalues();
  vectors = eig.eigenvectors();
  return true;
}

}  // namespace beamrail
