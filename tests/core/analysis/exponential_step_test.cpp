// The phi functions of a damped mode block B = [[0, 1], [-lambda, -c]] (exponential_step.hpp):
// against the undamped oscillator functions at c = 0, against the exponential of the augmented
// matrix in long double (Eigen's MatrixFunctions, an independent algorithm: Pade approximants
// with scaling and squaring), and their exponential against the closed-form free motion of a
// damped oscillator.
#include "core/analysis/exponential_step.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <unsupported/Eigen/MatrixFunctions>
#include <vector>

namespace beamrail {
namespace {

struct Phi {
  double alpha[5], beta[5];
};

Phi damped(double lambda, double c, double tau) {
  Phi f;
  damped_oscillator_phi(lambda, c, tau, f.alpha, f.beta);
  return f;
}

TEST(ExponentialStep, UndampedBlocksGiveTheOscillatorFunctions) {
  // phi_k(tau B) = g_k I + tau g_{k+1} B at x = lambda tau^2 when c = 0.
  double worst = 0.0;
  for (double lambda : {-2.5e3, -1.0, 0.0, 1e-6, 3.0, 400.0, 1e6, 4.4e9})
    for (double tau : {1e-7, 1e-4, 0.01, 0.3}) {
      const double x = lambda * tau * tau;
      const std::array<double, 5> g = oscillator_g(x);
      const Phi f = damped(lambda, 0.0, tau);
      for (int k = 0; k < 4; ++k) {
        const double scale =
            std::abs(g[k]) + std::abs(tau * g[k + 1]) * std::sqrt(std::abs(lambda));
        const double e =
            std::max(std::abs(f.alpha[k] - g[k]),
                     std::abs(f.beta[k] - tau * g[k + 1]) * std::sqrt(std::abs(lambda))) /
            std::max(scale, 1e-300);
        // cos s and sin s / s of s = sqrt(x): relative to the size of the terms, growing with s
        // (the rounding of x moves s by eps s / 2).
        const double bound = 1e-13 * (1.0 + std::sqrt(std::abs(x)));
        worst = std::max(worst, e / (1.0 + std::sqrt(std::abs(x))));
        EXPECT_LT(e, bound) << "lambda " << lambda << " tau " << tau << " k " << k;
      }
    }
  std::printf("damped phi at c = 0 against the oscillator functions: worst %.1e (1 + sqrt|x|)\n",
              worst);
}

// (alpha_k, beta_k), k = 0..4, from the exponential of the 10 x 10 block matrix
// [[tau S, I, 0, 0, 0], [0, 0, I, 0, 0], ..., [0, 0, 0, 0, 0]] (its first block row holds
// phi_k(tau S)), in long double, with S = D B D^-1 = [[0, w], [-lambda / w, -c]] balanced by
// D = diag(w, 1) (B itself, with entries 1 and lambda, scales too badly for the squarings):
// phi_k(tau S) = D phi_k(tau B) D^-1, so alpha_k is its (0, 0) entry and w beta_k its (0, 1).
std::vector<std::array<double, 2>> augmented_phi(double lambda, double c, double tau, double w) {
  using Matrix = Eigen::Matrix<long double, 10, 10>;
  Matrix a = Matrix::Zero();
  a(0, 1) = static_cast<long double>(w) * tau;
  a(1, 0) = -static_cast<long double>(lambda) / w * tau;
  a(1, 1) = -static_cast<long double>(c) * tau;
  for (int k = 0; k < 4; ++k) a.block<2, 2>(2 * k, 2 * k + 2).setIdentity();
  const Matrix e = a.exp();
  std::vector<std::array<double, 2>> out;
  for (int k = 0; k < 5; ++k)
    out.push_back({static_cast<double>(e(0, 2 * k)), static_cast<double>(e(0, 2 * k + 1) / w)});
  return out;
}

TEST(ExponentialStep, DampedFunctionsMatchTheAugmentedExponential) {
  // Light to heavy damping, small to large steps (the series below |z| = 2, the eigenvalues'
  // divided differences above), a negative and a zero stiffness, and damping just outside the
  // critical margin on either side.
  struct Case {
    double lambda, c;
  };
  std::vector<Case> cases = {{1.0, 0.02},       {2.5e3, 1.0},     {2.5e3, 120.0},  {4e6, 40.0},
                             {4e6, 2e4},        {4e6, 8e5},       {3.3e7, 1.65e4}, {1e10, 5e4},
                             {1e10, 1e7},       {-400.0, 3.0},    {0.0, 50.0},     {0.0, 1e-3},
                             {1e6, 0.99 * 2e3}, {1e6, 1.01 * 2e3}};
  cases.push_back({1e6, off_critical(1e6, 2e3 * (1.0 + 1e-9))});
  cases.push_back({1e6, off_critical(1e6, 2e3 * (1.0 - 1e-9))});
  // Negative damping (a force that feeds the motion; the integrator leaves it in its remainder,
  // but the functions hold for it).
  cases.push_back({2.5e3, -1.0});
  cases.push_back({4e6, -8e5});
  cases.push_back({1.0, -400.0});
  double worst = 0.0;
  for (const Case& m : cases)
    for (double tau : {1e-6, 1e-4, 2e-3, 0.05}) {
      const double w = std::sqrt(std::abs(m.lambda)) + 0.5 * std::abs(m.c);  // B's eigenvalues
      const double z = w * tau;
      if (z > 600.0 || (m.c < 0.0 && z > 30.0)) continue;  // the exponential's range
      const Phi f = damped(m.lambda, m.c, tau);
      const auto ref = augmented_phi(m.lambda, m.c, tau, w);
      for (int k = 0; k < 5; ++k) {
        const double a = ref[k][0], b = ref[k][1];
        const double scale = std::abs(a) + std::abs(b) * w;
        const double e = (std::abs(f.alpha[k] - a) + std::abs(f.beta[k] - b) * w) / scale;
        worst = std::max(worst, e);
        EXPECT_LT(e, 1e-12) << "lambda " << m.lambda << " c " << m.c << " tau " << tau << " k " << k
                            << ": " << f.alpha[k] << " " << a << ", " << f.beta[k] << " " << b;
      }
    }
  std::printf("damped phi against the augmented exponential: worst relative error %.1e\n", worst);
}

TEST(ExponentialStep, DampedExponentialIsTheFreeDampedOscillator) {
  // x'' + c x' + lambda x = 0 from x0, v0: exp(tau B) (x0, v0) against the closed forms
  // (underdamped, overdamped, and critical in the series' range).
  const double x0 = 0.3, v0 = -2.0;
  double worst = 0.0;
  struct Case {
    double lambda, c, tau;
  };
  for (const Case& m : std::vector<Case>{{400.0, 4.0, 0.37},
                                         {400.0, 4.0, 0.01},
                                         {400.0, 100.0, 0.2},
                                         {400.0, 100.0, 1e-3},
                                         {1e8, 2e4 * 0.3, 1e-3},
                                         {400.0, 40.0, 0.04}}) {  // critical: c^2 = 4 lambda
    const double s = 0.5 * m.c, d2 = s * s - m.lambda, t = m.tau;
    double x = 0.0, v = 0.0;
    if (d2 < 0.0) {
      const double wd = std::sqrt(-d2), e = std::exp(-s * t);
      x = e * (x0 * std::cos(wd * t) + (v0 + s * x0) / wd * std::sin(wd * t));
      v = e * (v0 * std::cos(wd * t) - (m.lambda * x0 + s * v0) / wd * std::sin(wd * t));
    } else if (d2 > 0.0) {
      const double r = std::sqrt(d2), r1 = -s + r, r2 = -s - r;
      const double a1 = (v0 - r2 * x0) / (r1 - r2), a2 = (r1 * x0 - v0) / (r1 - r2);
      x = a1 * std::exp(r1 * t) + a2 * std::exp(r2 * t);
      v = a1 * r1 * std::exp(r1 * t) + a2 * r2 * std::exp(r2 * t);
    } else {
      const double e = std::exp(-s * t), b = v0 + s * x0;
      x = e * (x0 + b * t);
      v = e * (b - s * (x0 + b * t));
    }
    const Phi f = damped(m.lambda, m.c, t);
    // (alpha I + beta B) (x0, v0) = (alpha x0 + beta v0, alpha v0 - beta (lambda x0 + c v0)).
    const double xf = f.alpha[0] * x0 + f.beta[0] * v0;
    const double vf = f.alpha[0] * v0 - f.beta[0] * (m.lambda * x0 + m.c * v0);
    const double w = std::sqrt(m.lambda);
    const double e = (std::abs(xf - x) * w + std::abs(vf - v)) / (std::abs(x0) * w + std::abs(v0));
    worst = std::max(worst, e);
    EXPECT_LT(e, 1e-13) << "lambda " << m.lambda << " c " << m.c << " tau " << t;
  }
  std::printf("damped exponential against the free damped oscillator: worst %.1e\n", worst);
}

TEST(ExponentialStep, DampingIsTakenOffCriticalByAtMostHalfTheMargin) {
  EXPECT_EQ(off_critical(1e6, 1e3), 1e3);
  EXPECT_EQ(off_critical(1e6, 5e3), 5e3);
  EXPECT_EQ(off_critical(-1.0, 2.0), 2.0);
  EXPECT_EQ(off_critical(0.0, 2.0), 2.0);
  for (double c : {1.999e3, 2e3, 2.004e3}) {
    const double moved = off_critical(1e6, c);
    EXPECT_NEAR(std::abs(0.25 * moved * moved - 1e6), kCriticalMargin * 1e6, 1e-6) << c;
    EXPECT_LT(std::abs(moved / c - 1.0), 0.5 * kCriticalMargin + 1e-3) << c;
    EXPECT_EQ(moved >= 2e3, c >= 2e3) << c;  // on the side it was
  }
}

}  // namespace
}  // namespace beamrail
