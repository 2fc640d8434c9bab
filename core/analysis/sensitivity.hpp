// Design sensitivities (docs/model.md "Design sensitivities"): derivatives of what the analyses
// report with respect to a design parameter p, at a converged result.
//
// A parameter p changes the Model (section constants, lengths, attachment offsets, masses, load
// values: everything the scene build derives from the numbers of the study file). The state is the
// bodies' displacements from their reference positions and their rotations from their initial
// orientations, so a state can be carried from the model at p to the model at p + h unchanged
// (transplant_state). The partial derivatives at a fixed state, dW/dp of the generalized forces and
// d/dp of phi^T K phi and phi^T M phi, come from the models at p + h and p - h (central
// differences of the model's quantities at one fixed state: smooth functions of p, evaluated to
// rounding, so the steps can be small; no analysis is repeated). Everything that depends on the
// state follows the exact formulas:
//
//  - static equilibrium W(u(p), p) = 0: du/dp = -S^-1 dW/dp|_u with S = dW/du the tangent at the
//    equilibrium (one solve per parameter with one factorization);
//  - a response r(u, p) of the equilibrium: dr/dp = d/dh r(u + h du/dp, p + h) at h = 0, the
//    derivative along the design direction (central difference of r at two states);
//  - an eigenvalue of K phi = lambda M phi (M-normalized phi) about the equilibrium:
//    dlambda/dp = phi^T (dK/dp - lambda dM/dp) phi, dK/dp and dM/dp the total derivatives along
//    the design direction (through u(p) too). A cluster of eigenvalues within kClusterGap of each
//    other has no derivative per eigenvalue: the derivatives of the cluster are the eigenvalues of
//    Phi^T (dK - lambda dM) Phi over its modes (the directional derivatives as p grows), assigned
//    in ascending order, and the result says so;
//  - a buckling factor of (K0 + lambda K1) phi = 0: dlambda/dp = -phi^T (dK0 + lambda dK1) phi /
//    (phi^T K1 phi).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/analysis/buckling_analysis.hpp"
#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// Eigenvalues closer than this (relative) are treated as one cluster.
inline constexpr double kClusterGap = 1e-6;
// Eigenvalues closer than this (relative) are reported as near a crossing: the derivative of each
// is exact, but it changes quickly with the design (the modes exchange character).
inline constexpr double kNearCrossing = 1e-3;

// Sets `to` (a Data of `to_model`, which has the same bodies and elements as `from_model`) to the
// state of `from`: each free body's displacement from its reference position and its rotation from
// its initial orientation.
void transplant_state(const Model& from_model, const Data& from, const Model& to_model, Data& to);

// The state of `base` (a Data of `base_model`) carried to `model` and moved by `increment`
// (dim n_dofs: dc, dtheta per free body, as apply_increment).
Data moved_state(const Model& base_model, const Data& base, const Model& model,
                 const Eigen::VectorXd& increment);

// The models at p + h and p - h.
struct DesignStep {
  const Model* plus = nullptr;
  const Model* minus = nullptr;
  double h = 0.0;
};

// du/dp of a static equilibrium: factors the tangent once, then one solve per parameter.
class EquilibriumSensitivity {
 public:
  // `data` holds the equilibrium of `model` under its loads at time t scaled by load_factor.
  EquilibriumSensitivity(const Model& model, const Data& data, double t, double load_factor = 1.0);
  ~EquilibriumSensitivity();
  // "" when the tangent could be factored; else why not (a free mechanism: no unique du/dp).
  const std::string& failure() const { return failure_; }
  // du/dp (dim n_dofs) for the design step; empty when failure() is not empty.
  Eigen::VectorXd state_derivative(const DesignStep& step) const;

 private:
  struct Factor;
  const Model& model_;
  const Data& data_;
  double t_, load_factor_;
  std::unique_ptr<Factor> factor_;
  std::string failure_;
};

// d/dh q(state + h v, p + h) at h = 0 by a central difference, for q evaluated on a model and a
// state: the total derivative of q along the design direction (v = du/dp, or empty when the state
// does not depend on p).
double directional_derivative(const Model& base_model, const Data& base, const DesignStep& step,
                              const Eigen::VectorXd& v,
                              const std::function<double(const Model&, const Data&)>& q);

struct EigenvalueDerivatives {
  std::vector<double> values;  // dlambda/dp per eigenvalue given
  // Per eigenvalue: 0 alone, 1 near a crossing (within kNearCrossing of another), 2 in a cluster
  // (within kClusterGap) that splits as p grows (the directional derivative as p grows), 3 in a
  // cluster that stays repeated (its members' derivatives are equal).
  std::vector<int> crossing;
};

// The derivatives of the eigenvalues `lambdas` (ascending: every one computed, so that clusters
// are found) of K phi = lambda M phi with M-normalized `shapes` (columns) about `base` (data of
// base_model), K the symmetric part of -dW/du at time t and load_factor (the tangent the modal
// analysis uses).
EigenvalueDerivatives eigenvalue_derivatives(const Model& base_model, const Data& base,
                                             const DesignStep& step, const Eigen::VectorXd& v,
                                             double t, double load_factor,
                                             const std::vector<double>& lambdas,
                                             const Eigen::MatrixXd& shapes);

// The derivatives of the buckling factors `factors` (ascending, every one computed) with shapes
// `shapes` (columns) about the reference state `base` (data of `reference`); the design steps give
// the reference structure (its constant loads) and the structure with the loads to scale at
// p +- h; v = du/dp of the reference state (empty when it is the unloaded initial state).
EigenvalueDerivatives buckling_factor_derivatives(const Model& reference, const Data& base,
                                                  const DesignStep& reference_step,
                                                  const DesignStep& scaled_step,
                                                  const Eigen::VectorXd& v, double t,
                                                  const std::vector<double>& factors,
                                                  const Eigen::MatrixXd& shapes);

}  // namespace beamrail
