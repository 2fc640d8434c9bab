// Linear buckling analysis (docs/model.md "Analyses", "Linear buckling"): the load factors lambda
// at which a structure, held in a reference state under loads that stay constant, loses its
// stiffness when further loads grow as lambda times their value:
//
//   (K0 + lambda K1) phi = 0,
//
// K0 the tangent stiffness (K = -d wrench / d (dc, dtheta)) at the reference state, K1 its
// derivative along the linear response u1 = K0^-1 P1 to the scaled loads P1: the stress
// (geometric) stiffness of the forces u1 puts in the elements, the change of the element stiffness
// with u1's geometry, and the load stiffness of forces at body points (their levers turn with the
// bodies). A factor lambda > 1 means the scaled loads can grow lambda-fold before the structure
// buckles, to first order (prebuckling rotations small).
//
// K1's element part is the central difference of the exact element tangent along u1 at two step
// sizes, extrapolated (Richardson): the factors it gives change by 1e-10 between steps ten times
// apart (measured; buckling_analysis.cpp). The load part is exact.
//
// The reference state's stiffness must be positive definite: every free body held (a free body or
// a carriage free along its rails has no stiffness against motion there, and a buckling factor
// along such a direction means nothing). Loads that are not conservative (torques of fixed
// direction and follower loads make the tangent non-symmetric) are refused: a follower load may
// lose stability by flutter, which the modal and static analyses detect and this one cannot.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/analysis/modal_analysis.hpp"
#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// EigenSolverKind::kAuto's choice for the buckling analysis: the dense solver (dense_eigen.hpp, one
// generalized eigensolution of -K1 x = mu K0 x) below 3 wanted + 24 degrees of freedom, Lanczos in
// Cholesky mode (Spectra, with K0's factors) from there. MEASURED
inline bool buckling_dense_is_faster(Eigen::Index dofs, Eigen::Index wanted) {
  return dofs < 3 * wanted + 24;
}

struct BucklingOptions {
  int modes = 1;                                          // lowest positive load factors wanted
  EigenSolverKind solver = EigenSolverKind::kAuto;        // kShiftInvert: Lanczos; kAuto:
                                                          // buckling_dense_is_faster
  double time = std::numeric_limits<double>::infinity();  // loads' time
  double max_seconds = 0.0;  // wall-clock budget [s]; 0: none (result.timed_out when spent)
  // Positive factors computed beyond `modes` into BucklingResult::guard (design sensitivities, as
  // ModalOptions::guard_modes); Lanczos then computes more pairs, which moves the factors' last
  // digits.
  int guard_modes = 0;
  // Whether the options can run: true, or false with the first problem in *error. The analysis
  // refuses options that are not valid; the study reader reports them.
  bool IsValid(std::string* error) const;
};

struct BucklingMode {
  double factor = 0.0;  // lambda [-]
  // The buckling shape (dim n_dofs): the largest of |translation| and |rotation| x the
  // characteristic length is 1, and the largest entry positive.
  Eigen::VectorXd shape;
  // |phi^T K(u0 + lambda u1) phi| / phi^T K0 phi: how much stiffness the shape keeps on the
  // linear prebuckling path at the factor, which the linearization K0 + lambda K1 takes as 0
  // (core/analysis/buckling_path.hpp); about the factor's relative uncertainty from what the
  // linearization leaves out.
  double nonlinearity = 0.0;
};

// Above this nonlinearity a mode's factor comes with a warning.
inline constexpr double kBucklingNonlinearityLimit = 1e-3;
// From this nonlinearity on the warning says the factor is no buckling load: the shape keeps half
// its stiffness or more where the linearization says it has none. A horizontal aluminium
// cantilever (12 x 20 mm, 0.8 m, 16 segments) bent about its weak axis by 3 N at its tip, which
// compresses nothing, gave the factor 1.61 at 0.75 (1.79 to 1.61 from 2 to 32 segments), while a
// static analysis at 100 times the load finds it stable (tests/core/analysis/buckling_test.cpp).
inline constexpr double kBucklingNotALoad = 0.5;

struct BucklingResult {
  bool ok = false;
  bool timed_out = false;
  std::string message;
  std::string solver;               // "dense" or "lanczos"
  std::vector<BucklingMode> modes;  // the lowest positive factors, ascending
  // The positive factors above them that BucklingOptions::guard_modes asked for (fewer where there
  // are no more), their nonlinearity not measured and no warning of their own.
  std::vector<BucklingMode> guard;
  // Positive factors found in all: fewer than asked for when the scaled loads compress too little
  // of the structure (a structure in tension does not buckle); the missing factors are infinite.
  int positive_factors = 0;
  double asymmetry = 0.0;  // of K1's element part, |K1 - K1^T| / |K1| (rounding: ~1e-10)
  double step = 0.0;       // the larger difference step along u1, as the largest rotation or
                           // strain it causes [rad or -]
  double wall_seconds = 0.0;
  std::vector<std::string> warnings;
};

// The matrices of the buckling eigenproblem about the state in data.pose (symmetric parts;
// `reference` and `scaled` as for solve_buckling), u1 = K0^-1 P1, and K0's Cholesky factors.
// Throws std::runtime_error when the problem does not apply (non-conservative loads, nothing to
// scale, K0 not positive definite). data.pose is left as it was; data.stiffness holds K0's blocks.
struct BucklingMatrices {
  Eigen::SparseMatrix<double> k0, k1;
  Eigen::VectorXd u1;
  double asymmetry = 0.0;  // of K1's element part
  std::shared_ptr<const Eigen::SimplicialLLT<Eigen::SparseMatrix<double>>> llt;
};
// `symmetric_reference`: refuse a reference state whose K0 is not symmetric (false for states near
// but not at an equilibrium, whose rounding-level asymmetry means nothing).
BucklingMatrices buckling_matrices(const Model& reference, const Model& scaled, double t,
                                   Data& data, bool symmetric_reference = true);

// Solves the buckling eigenproblem about the state in data.pose: `reference` is the structure
// with the loads that stay constant (data.pose is its equilibrium under them, or its initial
// state when it has none), `scaled` the same structure (the same bodies and elements) with the
// loads that lambda multiplies. Never throws.
BucklingResult solve_buckling(const Model& reference, const Model& scaled,
                              const BucklingOptions& options, Data& data);

// The k-th lowest positive factor (1-based), +infinity when the structure has fewer.
double buckling_factor(const BucklingResult& result, int k);

}  // namespace beamrail
