// Modal analysis (docs/model.md "Analyses"): small vibrations about the current configuration (a
// static equilibrium or the initial one). Mass matrix (blocks m I, A J A^T) and exact tangent
// stiffness K = -d wrench / d (dc, dtheta); the lowest modes of the generalized symmetric
// eigenproblem K x = w^2 M x come from the shifted inverse problem (K + mu M)^-1 M x = x / (w^2 +
// mu), solved densely (Eigen) for small scenes and by Lanczos (Spectra) for large ones.
//
// The shift mu is 0 when every free body is held by beams to a fixed body (K is then positive
// definite unless the loads buckle it), so the lowest eigenvalues are resolved to their own
// relative accuracy however wide the spectrum (a 100,000-segment chain spans 20 decades). Scenes
// with free bodies or rails may have rigid-body or mechanism modes: mu is then a small positive
// multiple of the stiffness scale.
//
// Torques of fixed direction and follower loads do no conservative work: at an equilibrium under
// them K is not
// symmetric (relative asymmetry above kModalAsymmetryLimit), and the modes are those of the
// non-symmetric problem (dense, or Arnoldi with shift-invert by a sparse LU); complex eigenvalues
// (flutter) fail the analysis.
//
// A mode is rigid when it deforms no element (core/analysis/element_deformation.hpp), never by the
// size of its eigenvalue: a soft elastic mode may have an eigenvalue 1e-20 of the stiffest one.
// Joints are elements: a mode that strains a joint's penalty is elastic (the run warns when one
// deforms joints and no beam or rail: its frequency is the penalty's), while a mechanism's motion
// that a joint allows (a pendulum swinging about its revolute joint) is rigid, its w^2 the load
// stiffness's.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <limits>
#include <string>
#include <vector>

#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

enum class EigenSolverKind { kAuto, kDense, kShiftInvert };

class SparseStructureCache;

// EigenSolverKind::kAuto's choice for the modal analysis: the dense solver (every eigenpair;
// dense_eigen.hpp) below `pairs` + 12 degrees of freedom, shift-invert Lanczos (Spectra) from
// there, `pairs` the eigenpairs Lanczos computes: the modes wanted, plus 12 for rigid modes unless
// every free body is held by beams. (Lanczos also needs 2 pairs degrees of freedom; below,
// solve_modal solves densely whatever was asked.) MEASURED
inline bool modal_dense_is_faster(Eigen::Index dofs, Eigen::Index pairs) {
  return dofs < pairs + 12;
}

struct ModalOptions {
  int modes = 6;                                    // elastic modes wanted
  EigenSolverKind solver = EigenSolverKind::kAuto;  // kAuto: modal_dense_is_faster
  // Shares the fill-reducing ordering of K + mu M between the analyses of one topology (the
  // designs of a sweep or optimization); nullptr: each shift-invert analysis makes its own. The
  // results are the same to the last bit either way.
  SparseStructureCache* structure_cache = nullptr;
  double time = std::numeric_limits<double>::infinity();  // loads' time (load stiffness)
  double load_factor = 1.0;  // 0: linearize the unloaded structure (no load stiffness)
  double max_seconds = 0.0;  // wall-clock budget [s]; 0: none (result.timed_out when spent)
  bool keep_mass = false;    // keep M in the result (to compare shapes)
  // Elastic modes computed beyond `modes` into ModalResult::guard (design sensitivities: a mode
  // repeated with the next one needs that one's shape, core/analysis/sensitivity.hpp). They take
  // no part in the result's modes, checks or warnings; shift-invert then computes more pairs, which
  // moves the modes' last digits.
  int guard_modes = 0;
  // Whether the options can run: true, or false with the first problem in *error. The analysis
  // refuses options that are not valid; the study reader reports them.
  bool IsValid(std::string* error) const;
};

struct Mode {
  // kElastic: deforms elements, w^2 > 0. kUnstable: deforms elements, w^2 < 0 (buckled or an
  // unstable equilibrium). kRigid: deforms no element (rigid-body or mechanism motion); its w^2
  // comes from the load stiffness only (a pendulum swings), 0 when that is below resolution.
  enum class Kind { kElastic, kRigid, kUnstable };
  Kind kind = Kind::kElastic;
  double eigenvalue = 0.0;    // w^2 [1/s^2]
  double frequency_hz = 0.0;  // sign(w^2) sqrt(|w^2|) / 2 pi [Hz]
  double deformation = 0.0;   // ElementDeformation::ratio of the shape
  // Rounding noise of the stiffness terms against the mode's inertia forces,
  // eps |D^-1/2 |K| |x|| / |w^2| with D = diag M: a frequency is resolved in double precision while
  // this is well below 1 (chains of thousands of very short segments reach it).
  double noise = 0.0;
  Eigen::VectorXd shape;  // M-normalized (x^T M x = 1), dim n_dofs; largest entry positive
  // Participation in rigid motions of the whole scene: gamma_d = x^T M r_d for unit translations
  // along global x, y, z (r_d: every centre moves by e_d) and unit rotations about the global x,
  // y, z axes through ModalResult::reference_point (r_d: centres move by e_d x (c - p), bodies
  // turn by e_d) [sqrt(kg), sqrt(kg) m]. The effective modal mass is gamma_d^2 [kg, kg m^2]; over
  // all modes (rigid ones included) it sums to ModalResult::rigid_mass.
  Vec6 participation = Vec6::Zero();
};

struct ModalResult {
  bool ok = false;         // false also when fewer elastic modes exist than asked for, or when
                           // a mode is unstable (the configuration is no stable equilibrium)
  bool timed_out = false;  // stopped by max_seconds
  std::string message;
  std::string solver;       // "dense" or "shift-invert"
  std::vector<Mode> modes;  // ascending eigenvalue; rigid-body modes included, marked
  // The elastic modes above them that ModalOptions::guard_modes asked for (fewer where the scene
  // has no more), unchecked.
  std::vector<Mode> guard;
  int rigid_modes = 0;
  double shift = 0.0;         // mu of the inverse problem [1/s^2]
  double asymmetry = 0.0;     // |K - K^T| / |K| of D K D, D = diag(M)^-1/2
  bool nonsymmetric = false;  // asymmetry > kModalAsymmetryLimit: the non-symmetric problem solved
  double wall_seconds = 0.0;
  std::vector<std::string> warnings;
  // r_d^T M r_d of the rigid motions of Mode::participation: the free bodies' total mass for
  // translations, their inertia about the global axes through reference_point for rotations.
  Vec6 rigid_mass = Vec6::Zero();
  // The free bodies' centre of mass in the configuration linearized about: the rotations'
  // reference, so that no translation is counted as a rotation about a distant origin [m].
  Vec3 reference_point = Vec3::Zero();
  Eigen::SparseMatrix<double> mass;  // M at the configuration, when ModalOptions::keep_mass
};

// The effective modal mass of each rigid motion over its total, gamma_d^2 / (r_d^T M r_d) (0 where
// the total is 0).
Vec6 effective_mass_fraction(const Mode& mode, const ModalResult& result);

// The names of the rigid motions of Mode::participation, in order.
inline constexpr const char* kDirectionNames[6] = {"x", "y", "z", "rx", "ry", "rz"};

// The direction (0..5: x, y, z, rx, ry, rz) with the largest effective mass fraction, or -1 when
// the mode moves the scene's mass in no rigid direction.
int dominant_direction(const Mode& mode, const ModalResult& result);

// The modal assurance criterion of two shapes weighted by a mass matrix,
// (a^T M b)^2 / ((a^T M a) (b^T M b)): 1 for the same shape, 0 for M-orthogonal ones.
double modal_assurance(const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                       const Eigen::SparseMatrix<double>& m);

// A frequency's relative error from rounding is about kModalNoiseError x its mode's noise
// (Mode::noise). Measured on a 1 kg tip cantilever of 10 mm steel in N segments: noise 1.8e-5 at
// N = 300 (error < 3e-8), 2.1e-3 at 1,000 (4.4e-7), 0.17 at 3,000 (4.1e-5), 22 at 10,000
// (2e-2). Above kModalNoiseWarning (an error above ~1e-7) the run warns; above kModalNoiseLimit
// (~1e-3) the frequencies are not resolved and the analysis fails.
inline constexpr double kModalNoiseError = 1e-3;
inline constexpr double kModalNoiseWarning = 1e-4;
inline constexpr double kModalNoiseLimit = 1.0;
// Above this asymmetry the non-symmetric eigenproblem of K is solved (torques of fixed direction,
// follower loads;
// rounding leaves ~1e-15), below it the symmetric one of its symmetric part.
inline constexpr double kModalAsymmetryLimit = 1e-10;

// Solves the eigenproblem about the configuration in data.pose. Never throws.
ModalResult solve_modal(const Model& model, const ModalOptions& options, Data& data);

// Dense solution of K x = w^2 M x (K symmetric, M symmetric positive definite): every eigenvalue,
// ascending, and M-normalized eigenvectors. Eigenvalues of the direct problem are accurate to
// ~eps lambda_max absolute; when shift >= 0 is given and K + shift M can be factored, the lower
// part of the spectrum comes from the inverse problem (K + shift M)^-1 M, accurate to ~eps
// (lambda + shift) instead. Without a shift (negative), the inverse problem is used only when K
// is positive definite and the spectrum spans more than 6 decades. False when the dense
// solver fails (core/analysis/dense_eigen.hpp: LAPACK from 100 rows, Eigen below).
bool solve_dense_eigenproblem(const Eigen::MatrixXd& k, const Eigen::MatrixXd& m,
                              Eigen::VectorXd& values, Eigen::MatrixXd& vectors,
                              double shift = -1.0);

// Dense solution of the non-symmetric K x = lambda M x (M symmetric positive definite) through
// A = L^-1 K L^-T, M = L L^T: every eigenvalue, and when `vectors` is given the eigenvectors
// L^T x (columns). False when M is not positive definite or Eigen's solver fails.
bool solve_dense_nonsymmetric(const Eigen::MatrixXd& k, const Eigen::MatrixXd& m,
                              Eigen::VectorXcd& values, Eigen::MatrixXcd* vectors = nullptr);

// The `count` eigenvalues of the non-symmetric K x = lambda M x nearest -shift (Arnoldi with
// shift-invert by a sparse LU; count < rows - 2). False when M is not positive definite, K + shift
// M cannot be factored or Arnoldi does not converge.
bool nonsymmetric_eigenvalues_near(const Eigen::SparseMatrix<double>& k,
                                   const Eigen::SparseMatrix<double>& m, double shift,
                                   Eigen::Index count, Eigen::VectorXcd& values);

// The k-th non-rigid mode (1-based; elastic or unstable), or nullptr.
const Mode* elastic_mode(const ModalResult& result, int k);

}  // namespace beamrail
