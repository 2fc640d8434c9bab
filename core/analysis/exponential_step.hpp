// The step of the modal integrator (core/analysis/modal_integrator.hpp): functions of the 2 x 2
// mode blocks B_i = [[0, 1], [-lambda_i, -c_i]] (c_i a mode's damping, often 0) and the
// coefficient functions of the stiff-order-4 exponential Runge-Kutta method of Hochbruck and
// Ostermann (2005) with its embedded solutions.
#pragma once

#include <Eigen/Core>
#include <array>

namespace beamrail {

// g_m(x) = sum_j (-x)^j / (2j + m)!, m = 0..4, at x = lambda tau^2: the phi functions of a mode
// block B = [[0, 1], [-lambda, 0]] are phi_k(tau B) = g_k I + tau g_{k+1} B (B^2 = -lambda I).
// Any sign of lambda (negative: an unstable mode).
std::array<double, 5> oscillator_g(double x);

// phi_k(tau B), k = 0..4, of a damped mode block B = [[0, 1], [-lambda, -c]] (any signs of c and
// lambda) as alpha_k I + beta_k B; with c = 0, alpha_k = g_k and beta_k = tau g_{k+1} at
// x = lambda tau^2 (oscillator_g). Where the eigenvalues z of tau B are small (|z| < 2) from the
// series sum_j (tau B)^j / (j + k)!, else from the scalar phi_k at the two eigenvalues (divided
// differences). Near critical damping (c^2 / 4 close to lambda) with |z| >= 2 the divided
// differences lose about a factor sqrt(lambda / |c^2 / 4 - lambda|), and at critical damping
// they are not defined: a mode's damping is first taken off_critical.
void damped_oscillator_phi(double lambda, double c, double tau, double alpha[5], double beta[5]);

// A damping c >= 0 of a mode of eigenvalue lambda at least kCriticalMargin lambda away from
// critical in c^2 / 4 - lambda: c itself, or moved to the nearer side's edge (by at most half of
// kCriticalMargin relative). The modal integrator gives its modes' blocks this damping and
// leaves the difference in its remainder (exact in sum).
inline constexpr double kCriticalMargin = 1e-2;
double off_critical(double lambda, double c);

// Per mode a row: (eta, nu), or (x, u) in the physical basis.
using ModeBlock = Eigen::Matrix<double, Eigen::Dynamic, 2>;

// The linear part of the modes: B_i = [[0, 1], [-lambda_i, -damping_i]]; damping empty: every
// mode undamped.
struct ModeBlocks {
  Eigen::ArrayXd lambda;
  Eigen::ArrayXd damping;
  Eigen::Index size() const { return lambda.size(); }
  bool damped() const { return damping.size() > 0; }
};

// A function of the mode blocks B_i = [[0, 1], [-lambda_i, 0]], f(B_i) = alpha_i I + beta_i B_i.
struct ModeFunction {
  Eigen::ArrayXd alpha, beta;
  ModeFunction() = default;
  explicit ModeFunction(Eigen::Index n) : alpha(Eigen::ArrayXd::Zero(n)), beta(alpha) {}
  bool empty() const { return alpha.size() == 0; }  // a zero coefficient: skipped
};

// out += s f(B) z for the `count` modes from `begin` (inline: every stage of every step calls
// it). Each mode's value is the same whatever the range it is computed in.
inline void apply_add(const ModeFunction& f, const ModeBlocks& blocks, const ModeBlock& z,
                      ModeBlock& out, double s, Eigen::Index begin, Eigen::Index count) {
  const auto a = z.col(0).segment(begin, count).array();
  const auto b = z.col(1).segment(begin, count).array();
  const auto alpha = f.alpha.segment(begin, count), beta = f.beta.segment(begin, count);
  const auto lambda = blocks.lambda.segment(begin, count);
  out.col(0).segment(begin, count).array() += s * (alpha * a + beta * b);
  if (blocks.damped())
    out.col(1).segment(begin, count).array() +=
        s * (alpha * b - beta * (lambda * a + blocks.damping.segment(begin, count) * b));
  else
    out.col(1).segment(begin, count).array() += s * (alpha * b - beta * lambda * a);
}

// out += s f(B) z for every mode.
inline void apply_add(const ModeFunction& f, const ModeBlocks& blocks, const ModeBlock& z,
                      ModeBlock& out, double s = 1.0) {
  apply_add(f, blocks, z, out, s, 0, z.rows());
}

// The coefficient functions of one step of size h of the stiff-order-4 exponential Runge-Kutta
// method (5 stages, c = 0, 1/2, 1/2, 1, 1/2):
//   Z_i = E(c_i h) z + h sum_j a_ij N_j,   z+ = E(h) z + h sum_j b_j N_j.
// Why five stages (measured 2026-11-27, docs/transient_measurements.md "The tower over rtol and
// atol"): the four-stage methods of Krogstad and of Strehmel and Weiner (c = 0, 1/2, 1/2, 1; stiff
// order 3) save one evaluation and two products per step; Krogstad's ran the braced tower of
// docs/transient_measurements.md at rtol 1e-6, atol 1e-9 in 6.75 against 8.10 s with the same steps
// (3,972 against 3,970) and errors (rotations 5.7e-6 against 5.5e-6). But their stages give no
// embedded third-order solution other than the method's own, so only the second-order estimate
// controlled the step, and on rotating scenes the errors of both grew: the tumbling pair 3.8 .. 6.6
// rtol in its centres (this method 0.08 .. 0.39; with only its second-order estimate 0.11 .. 3.4),
// the fast spin of transient_auto_test.cpp 36 rtol, the bob hinged to a cantilever
// (joint_transient_test.cpp) 36 rtol at rtol 1e-7, the tumbling pair's energy over 10 s 955 rtol.
// Measured again (2026-11-30) with an embedded third-order solution for Krogstad's method (stage
// 3 alone with weight 4 phi2 - 8 phi3 where the method takes stages 2 and 3 with 2 phi2 - 4 phi3
// each: the distance h (2 phi2 - 4 phi3) (N2 - N3)), used where no part turns with a frame and no
// body moves as a mechanism: the tower at rtol 1e-6, atol 1e-9 took 3,972 steps in 6.96 against
// 8.20 s with the same errors (centres 1.24e-7 against 1.29e-7 of the motion, rotations equal),
// and the proportionality tests passed; but on the reference cantilever in 4 segments at fixed
// steps of 1 .. 0.125 ms its error was 10 to 20 times this method's (7.4e-6 against 7.7e-7 at
// 1 ms), and adaptive at the same rtol 2 to 10 times (the same steps: the second-order estimate
// holds them), so for a given error it costs more wherever the method's own error shows. Not
// taken.
// An estimate from the new state's forcing (first same as last, free: h (4 phi3 - phi2)
// (N(z+) - N4)) came out about a hundred times below the second-order one and changed nothing.
struct StepFunctions {
  static constexpr int kStages = 5;
  static constexpr double c[kStages] = {0.0, 0.5, 0.5, 1.0, 0.5};
  double h = 0.0;
  ModeFunction e_half, e_full;
  ModeFunction a[kStages][kStages];
  ModeFunction b[kStages];
  ModeFunction low[2];  // the embedded order-2 method: b1 = phi1 - 2 phi2, b2 = 2 phi2
  // The embedded third-order solution takes stage 3 (c = 1/2, local order 3) where the
  // fourth-order one takes stage 5 with the same weight b5 = 4 phi2 - 8 phi3: the two differ by
  // h b5 (N5 - N3), O(h^4).

  // The functions of step `step` for the modes' blocks.
  void compute(double step, const ModeBlocks& blocks);
};

}  // namespace beamrail
