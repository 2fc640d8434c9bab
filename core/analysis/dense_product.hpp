// Products of a dense matrix with one, two or six vectors: the modal integrator's changes of basis,
// ten to twenty per step on matrices up to 1200 x 1200 (every mode) or n x m (a band of m modes of
// n degrees of freedom, 6000 x 95 and more).
//
// Eigen's product of a dynamic matrix with an n x 2 block takes its matrix-matrix path, which
// repacks the big factor on every call; as two matrix-vector products it is twice as fast, and
// this kernel (both columns in one pass over the matrix, eight matrix columns at a time, compiled
// for several instruction sets with the one the CPU has chosen at load time) twice again:
// measured at n = 240 on the reference machine, 28 us, 15 us and 7.1 us.
#pragma once

#include <Eigen/Core>

namespace beamrail {

// y = a x for the column-major arrays x (a.cols() x 2) and y (a.rows() x 2): two vectors side by
// side.
void multiply_pair(const Eigen::MatrixXd& a, const double* x, double* y);

// y = a x for x (a.cols() x 6) and y (a.rows() x 6), column-major: three pairs in one pass (a
// trial step's new state and its two error estimates).
void multiply_three_pairs(const Eigen::MatrixXd& a, const double* x, double* y);

// y = a x for the vectors x (length a.cols()) and y (length a.rows()).
void multiply_vector(const Eigen::MatrixXd& a, const double* x, double* y);

}  // namespace beamrail
