// Products of a dense n x n matrix with one or two vectors: the modal integrator's changes of
// basis, ten to twenty per step on matrices up to 1200 x 1200.
//
// Eigen's product of a dynamic matrix with an n x 2 block takes its matrix-matrix path, which
// repacks the big factor on every call; as two matrix-vector products it is twice as fast, and
// this kernel (both columns in one pass over the matrix, eight matrix columns at a time, compiled
// for several instruction sets with the one the CPU has chosen at load time) twice again:
// measured at n = 240 on the reference machine, 28 us, 15 us and 7.1 us.
#pragma once

#include <Eigen/Core>

namespace beamrail {

// y = a x for the column-major n x 2 arrays x and y (two vectors side by side). a is n x n.
void multiply_pair(const Eigen::MatrixXd& a, const double* x, double* y);

// y = a x for the vectors x and y of length n.
void multiply_vector(const Eigen::MatrixXd& a, const double* x, double* y);

}  // namespace beamrail
