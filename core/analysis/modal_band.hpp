// Choosing the band of a band-limited modal run for an accuracy (IntegratorOptions::choose_band,
// "max_frequency_hz": "auto"; core/analysis/modal_integrator.hpp).
//
// A band-limited run keeps the modes above the band quasi-static: each follows its static
// response to the forcing and never rings. What that drops is the ringing those modes would do:
//   - the initial state's offset from the linearization: what rings is the response to the
//     force out of balance there, g = M0 a(x0, v0) (with the initial velocities: gyroscopic forces,
//     damping), like a load that jumps (below); the
//     offset itself is not decomposed: its second-order parts (a bent beam's shortening) follow
//     the motion rather than ring;
//   - an initial velocity v0: amplitude |phi_k c_k| / w_k; bounded by |v0 - Phi_m Phi_m^T M0 v0|
//     / w_(m+1);
//   - a load that jumps (a step after the start): mode k rings at its static response
//     phi_k phi_k^T F / w_k^2; dropped: R F, R = K0^-1 - Phi_m Lambda_m^-1 Phi_m^T (computed as
//     (K0 + mu M0)^-1 F - Phi_m (Lambda_m + mu)^-1 Phi_m^T F, mu a small shift that keeps rigid
//     and mechanism modes regular: they are always kept);
//   - a load that changes smoothly at a rate r [rad/s] (a ramp of duration T: r = kinks / T; a
//     harmonic load of frequency f: r = 2 pi f; a table: the sum of its slope changes) rings a
//     mode of frequency w at about r / w of its static response: R F r / w_(m+1).
// Each is a sum over the modes dropped: of the parts' magnitudes (a bound for every time) and,
// once they have dephased within 1 / w_(m+1) of the start, about their root sum of squares, which
// peaks at a few times that over a run's samples. Per body and direction, the amplitude is the
// smaller of the sum and kBandPeakOverRms times the root sum of squares; the modes above those
// computed count in full. Modes below kBandResonanceMargin times a harmonic load's frequency are
// always kept.
// The estimate is the sum over the excitations of those amplitudes, largest over the translations
// of the body centres the run's accuracy is measured at (the scene's own bodies, not the interior
// bodies of segmented beams: optimizer/run/trajectory.hpp), divided by the size of the motion (the
// largest elastic translation of the static responses to g and the loads, and of v0 / w_1); the
// rotations only when nothing translates (so a response point away from a body's centre, which
// also turns with it, is not covered). A run shorter than a quarter of the lowest elastic period
// (the horizon) moves less than those responses: there the size of a jump's or an initial
// velocity's motion is its modes' linear response at 32 times up to the horizon (a 201-body
// cantilever run for 10 ms, a twelfth of its period, chose bands that left 11 rtol of its own
// motion; tests/core/analysis/transient_auto_band_test.cpp); a smooth load's is not reduced. The
// nonlinear forcing is not in it: the modal method is for motions near its linearization (what
// the quasi-static modes then miss, their inertia, is checked during the run:
// core/analysis/quasi_static_modes.hpp). The band
// is the smallest number of modes (never splitting a cluster of equal frequencies, never leaving
// out a rigid or mechanism mode) whose estimate is at most the tolerance. An estimate, not a bound:
// on a cantilever (tests/core/analysis/modal_band_test.cpp) the bands chosen for rtol 1e-3 .. 1e-6
// made errors of 0.42 .. 0.53 times it against the full model.
#pragma once

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <string>
#include <vector>

#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// The peak of the dropped modes' dephased ringing over a run's samples, in root sums of squares
// (measured against full-model runs in tests/core/analysis/modal_band_test.cpp).
inline constexpr double kBandPeakOverRms = 3.0;

struct BandExcitation {
  enum class Kind { kVelocity, kForce };
  Kind kind = Kind::kForce;
  Eigen::VectorXd vector;  // per degree of freedom: [m/s, rad/s] or [N, N m]
  double rate = 0.0;       // kForce: 0 for a jump, else how fast it changes [rad/s]
  double factor = 1.0;     // kForce: the load's largest time factor (a table's largest value)
  bool harmonic = false;   // kForce: a harmonic load (rate its angular frequency)
  // kForce: how the load's factor changes from t0 on (absolute times); none: a jump at t0 (the
  // force out of balance at the start). choose_band follows it over a short run's horizon.
  const TimeFunction* time = nullptr;
  double t0 = 0.0;
};

// Modes below this times a harmonic load's angular frequency are always kept: quasi-static, they
// would miss their amplification near resonance.
inline constexpr double kBandResonanceMargin = 3.0;

struct BandChoice {
  Eigen::Index modes = 0;  // modes kept (the lowest)
  double estimate = 0.0;   // the dropped ringing over the motion (above) with these modes
  bool met = false;        // estimate <= tolerance
};

// The smallest number of the lowest modes whose estimate is within `tolerance`. `lambda`
// ascending w^2 of the M0-normalized columns of `phi` (the lowest of the model, possibly not all
// of them; the modes not among them count as dropped); `shifted` factors K0 + mu M0; `watched`
// the free-body indices measured (every body when empty); `horizon` the run's duration [s] (0:
// unbounded). When no number of the modes given meets the tolerance: all of them, met false.
// With `fixed` > 0: the estimate of the lowest `fixed` modes (a band given), met when within it.
// `rigid`: how many of the lowest modes are rigid-body or mechanism modes; -1: those whose w^2 is
// at most 1e-8 of the largest given (solve_band_modes for a given band counts those that deform
// no element instead, core/analysis/element_deformation.hpp: from 28 segments on, the dense basis
// of the cantilever of tests/core/analysis/modal_band_test.cpp reaches w^2 ~ 3e10 in its
// segments' torsion, and the rule took its first bending modes for rigid: the estimate of a 30 Hz
// band for its tip's initial velocity went from 6.2e-3 of the motion to 1.3).
BandChoice choose_band(const Eigen::VectorXd& lambda, const Eigen::MatrixXd& phi,
                       const Eigen::SparseMatrix<double>& m0,
                       const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& shifted, double mu,
                       const std::vector<BandExcitation>& excitations,
                       const std::vector<int>& watched, double tolerance, double horizon = 0.0,
                       Eigen::Index fixed = 0, Eigen::Index rigid = -1);

// The free-body indices of the scene's own bodies (not generated by segmenting a beam); all free
// bodies when none is.
std::vector<int> watched_bodies(const Model& model);

// The excitations of a run from t0 on: the force out of balance at the initial state and its
// velocity (per degree of freedom, empty or zero when none) and every load whose value changes
// after t0 and before t0 + horizon (0: unbounded) (steps, ramps, harmonic loads, tables), its
// generalized force at the pose of `data` (the linearization).
std::vector<BandExcitation> band_excitations(const Model& model, const Data& data,
                                             const Eigen::VectorXd& unbalanced,
                                             const Eigen::VectorXd& velocity, double t0,
                                             double horizon = 0.0);

// The modes of a band-limited run (core/analysis/modal_integrator.hpp): from the dense eigensolver
// up to kModalDenseBandMaxDofs degrees of freedom, else from shift-invert Lanczos asked for more
// modes until one lies above the band or, for a band chosen for rtol (band_hz 0), until the band
// meets rtol (at most kModalChosenBandMaxModes modes). k0 and m0: the symmetric tangent stiffness
// and the mass of the linearization posed in `data`; `excitations` and `watched` as for
// choose_band (for a given band, its estimate when there are excitations). False with *error
// when the eigensolver fails, the stiffness is singular, no band meets rtol, or no mode lies
// below a given band.
struct BandModes {
  Eigen::VectorXd values;   // w^2 of the modes computed, ascending
  Eigen::MatrixXd vectors;  // their M0-normalized shapes, n x values.size()
  Eigen::Index kept = 0;    // the lowest `kept` modes are integrated
  double top = 0.0;         // the band's top w^2: the highest mode kept (at least the lowest
                            // elastic one) or the given band's
  Eigen::Index needed = 0;  // a chosen band: the modes rtol needs (kept may be all of them)
  double estimate = -1.0;   // a chosen band: its estimate (0 when every mode is kept); -1: given
  double given_estimate = -1.0;  // a given band: its estimate; -1: none (no excitation given)
};
bool solve_band_modes(const Model& model, const Data& data, double t0,
                      const Eigen::SparseMatrix<double>& k0, const Eigen::SparseMatrix<double>& m0,
                      double band_hz, const std::vector<BandExcitation>& excitations,
                      const std::vector<int>& watched, double rtol, double max_seconds,
                      BandModes& out, std::string* error, double horizon = 0.0);

}  // namespace beamrail
