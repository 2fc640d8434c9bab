// Generalized coordinates of the static and modal analyses: 6 per free body, the displacement of
// the centre of mass dc and a rotation increment dtheta (global axes, A -> exp([dtheta]x) A), in
// free-body order (dim model.n_dofs).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// The wrenches of the free bodies (force, moment about the centre; global), dim n_dofs.
Eigen::VectorXd wrench_vector(const Model& model, const Data& data);

// d wrench / d (dc, dtheta) assembled from data.stiffness (n_dofs x n_dofs).
Eigen::SparseMatrix<double> stiffness_matrix(const Model& model, const Data& data);

// The symmetric part of the stiffness K = -S, -(S + S^T) / 2, block by block from data.stiffness
// and the blocks' transposes (no sparse transposes or sums: a 100,000-body chain has 1e7
// entries). *asymmetry = |W (S - S^T) W| / |W S W| (Frobenius norms, W = diag(weight)): with
// weights that make the entries comparable (1 / sqrt(M_ii), or 1 / sqrt(|S_ii|)) it does not
// depend on the units of length and angle. K is symmetric at an equilibrium under conservative
// loads (rounding leaves ~1e-15); torques of fixed direction and follower loads make it
// non-symmetric.
Eigen::SparseMatrix<double> symmetric_stiffness(const Model& model, const Data& data,
                                                const Eigen::VectorXd& weight, double* asymmetry);

// Weights 1 / sqrt(|S_ii|) of symmetric_stiffness (1 where S_ii is 0), from data.stiffness.
Eigen::VectorXd stiffness_weights(const Model& model, const Data& data);

// The mass matrix in these coordinates: blocks m I and A J A^T (n_dofs x n_dofs).
Eigen::SparseMatrix<double> mass_matrix(const Model& model, const Data& data);

// K X for the symmetric part K = -(S + S^T) / 2 of the tangent (as symmetric_stiffness) and a
// block of vectors X (n_dofs x m), from the tangent's blocks without assembling K.
Eigen::MatrixXd symmetric_stiffness_product(const Model& model, const Data& data,
                                            const Eigen::MatrixXd& x);

// M X, M the mass matrix (as mass_matrix), without assembling M.
Eigen::MatrixXd mass_product(const Model& model, const Data& data, const Eigen::MatrixXd& x);

// Moves the free bodies by dx: c += dc, q <- quat(dtheta) (x) q; updates pose (at rest) and the
// bodies' rotation vectors (data.rotation, followed through pi).
void apply_increment(const Model& model, Data& data, const Eigen::VectorXd& dx);

// Resets every free body to its initial pose, at rest.
void reset_to_initial(const Model& model, Data& data);

}  // namespace beamrail
