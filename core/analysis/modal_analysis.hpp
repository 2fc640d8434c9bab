// Modal analysis (DESIGN.md §2): small vibrations about the current configuration (a static
// equilibrium or the initial one). Mass matrix (blocks m I, A J A^T) and exact tangent stiffness
// K = -d wrench / d (dc, dtheta); the generalized symmetric eigenproblem K x = w^2 M x is solved
// densely (Eigen) for small scenes and by shift-invert Lanczos (Spectra) for large ones.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

enum class EigenSolverKind { kAuto, kDense, kShiftInvert };

struct ModalOptions {
  int modes = 6;  // elastic modes wanted
  EigenSolverKind solver = EigenSolverKind::kAuto;
  int dense_limit = 600;  // kAuto: dense up to this many degrees of freedom
  double time = std::numeric_limits<double>::infinity();  // loads' time (load stiffness)
  double load_factor = 1.0;  // 0: linearize the unloaded structure (no load stiffness)
};

struct Mode {
  enum class Kind { kElastic, kRigid, kUnstable };
  Kind kind = Kind::kElastic;
  double eigenvalue = 0.0;    // w^2 [1/s^2]
  double frequency_hz = 0.0;  // sqrt(w^2) / 2 pi; 0 for rigid modes; -sqrt(-w^2)/2 pi if unstable
  Eigen::VectorXd shape;      // M-normalized (x^T M x = 1), dim n_dofs; largest entry positive
};

struct ModalResult {
  bool ok = false;
  std::string message;
  std::string solver;       // "dense" or "shift-invert"
  std::vector<Mode> modes;  // ascending eigenvalue; rigid-body modes included, marked
  int rigid_modes = 0;
  double asymmetry = 0.0;  // |K - K^T| / |K| of D K D, D = diag(M)^-1/2, before symmetrizing
  double wall_seconds = 0.0;
  std::vector<std::string> warnings;
};

// Eigenvalues with |w^2| below this fraction of the largest are rigid-body (zero) modes. The dense
// solver compares with the largest of each group of bodies coupled by stiffness.
constexpr double kRigidModeThreshold = 1e-12;

// Solves the eigenproblem about the configuration in data.pose. Never throws.
ModalResult solve_modal(const Model& model, const ModalOptions& options, Data& data);

// Dense solution of K x = w^2 M x (K symmetric, M symmetric positive definite): every eigenvalue,
// ascending, and M-normalized eigenvectors. Eigenvalues come out accurate to ~eps lambda_max
// absolute, so when the spectrum spans many decades and K is positive definite (no rigid modes),
// the lower half is taken from the inverse problem M x = (1/w^2) K x, accurate to ~eps lambda_min.
// False when Eigen's solver fails.
bool solve_dense_eigenproblem(const Eigen::MatrixXd& k, const Eigen::MatrixXd& m,
                              Eigen::VectorXd& values, Eigen::MatrixXd& vectors);

// The k-th elastic mode (1-based), or nullptr.
const Mode* elastic_mode(const ModalResult& result, int k);

}  // namespace beamrail
