#include "core/analysis/exponential_step.hpp"

#include <cmath>
#include <complex>

namespace beamrail {

namespace {

// The Taylor coefficients (-1)^j / (2j + m)! of g_m, j = 0..kTerms-1: at |x| < 4 the next term
// is below 1e-22 of the first.
constexpr int kTerms = 13;
template <int m>
constexpr std::array<double, kTerms> oscillator_coefficients() {
  std::array<double, kTerms> c{};
  double f = 1.0;  // (2j + m)!
  for (int i = 2; i <= m; ++i) f *= i;
  for (int j = 0; j < kTerms; ++j) {
    c[j] = (j % 2 ? -1.0 : 1.0) / f;
    f *= (2.0 * j + m + 1) * (2.0 * j + m + 2);
  }
  return c;
}

template <int m>
double oscillator_series(double x) {
  static constexpr std::array<double, kTerms> c = oscillator_coefficients<m>();
  double sum = c[kTerms - 1];
  for (int j = kTerms - 2; j >= 0; --j) sum = sum * x + c[j];
  return sum;
}

using Complex = std::complex<double>;

// 1 / n!, n = 0..kSeriesTerms + 4.
constexpr int kSeriesTerms = 32;  // at |z| < 2 the last term is below 2^32 / 32! = 1.6e-26
constexpr std::array<double, kSeriesTerms + 5> inverse_factorials() {
  std::array<double, kSeriesTerms + 5> f{};
  double v = 1.0;
  for (int n = 0; n < kSeriesTerms + 5; ++n) {
    if (n > 0) v /= n;
    f[n] = v;
  }
  return f;
}
constexpr std::array<double, kSeriesTerms + 5> kInverseFactorial = inverse_factorials();

// Below this size of the eigenvalues of tau B the damped phi functions are summed as series.
constexpr double kSeriesRadius = 2.0;

// The scalar phi_k(z), k = 0..4: the series sum_j z^j / (j + k)! at |z| < kSeriesRadius, else
// phi_0 = e^z, phi_{k+1} = (phi_k - 1 / k!) / z (at |z| >= 2 the subtractions lose at most a
// few bits over the four levels).
void scalar_phi(Complex z, Complex out[5]) {
  if (std::abs(z) < kSeriesRadius) {
    for (int k = 0; k < 5; ++k) {
      Complex sum = kInverseFactorial[kSeriesTerms - 1 + k];
      for (int j = kSeriesTerms - 2; j >= 0; --j) sum = sum * z + kInverseFactorial[j + k];
      out[k] = sum;
    }
    return;
  }
  out[0] = std::exp(z);
  for (int k = 0; k < 4; ++k) out[k + 1] = (out[k] - kInverseFactorial[k]) / z;
}

}  // namespace

void damped_oscillator_phi(double lambda, double c, double tau, double alpha[5], double beta[5]) {
  // T = tau B satisfies T^2 = -p I - 2 s T with p = lambda tau^2, s = c tau / 2; its eigenvalues
  // are z = -s +- sqrt(s^2 - p).
  const double p = lambda * tau * tau, s = 0.5 * c * tau;
  const double d2 = s * s - p;
  const Complex root = std::sqrt(Complex(d2, 0.0));
  // The larger eigenvalue in size directly, the other from their product p (no cancellation;
  // -s and the root of the same sign, whatever the sign of c).
  const Complex big = s >= 0.0 ? -s - root : -s + root;
  const Complex small = std::abs(big) > 0.0 ? Complex(p, 0.0) / big : Complex(0.0, 0.0);
  if (std::abs(big) < kSeriesRadius) {
    // T^j = P_j I + Q_j T: T^{j+1} = -p Q_j I + (P_j - 2 s Q_j) T; phi_k(T) = sum_j T^j / (j+k)!.
    double sp[5] = {0, 0, 0, 0, 0}, sq[5] = {0, 0, 0, 0, 0};
    double pj = 1.0, qj = 0.0;
    for (int j = 0; j < kSeriesTerms; ++j) {
      for (int k = 0; k < 5; ++k) {
        sp[k] += pj * kInverseFactorial[j + k];
        sq[k] += qj * kInverseFactorial[j + k];
      }
      const double next_p = -p * qj;
      qj = pj - 2.0 * s * qj;
      pj = next_p;
    }
    for (int k = 0; k < 5; ++k) {
      alpha[k] = sp[k];
      beta[k] = tau * sq[k];
    }
    return;
  }
  // f(T) = a I + b T with f(z_i) = a + b z_i: b = (f(z1) - f(z2)) / (z1 - z2),
  // a = (z1 f(z2) - z2 f(z1)) / (z1 - z2). Real for real or complex-conjugate eigenvalues.
  Complex f1[5], f2[5];
  scalar_phi(big, f1);
  scalar_phi(small, f2);
  const Complex gap = big - small;
  for (int k = 0; k < 5; ++k) {
    alpha[k] = ((big * f2[k] - small * f1[k]) / gap).real();
    beta[k] = tau * ((f1[k] - f2[k]) / gap).real();
  }
}

double off_critical(double lambda, double c) {
  if (!(lambda > 0.0) || std::abs(0.25 * c * c - lambda) >= kCriticalMargin * lambda) return c;
  return 2.0 * std::sqrt(lambda *
                         (0.25 * c * c >= lambda ? 1.0 + kCriticalMargin : 1.0 - kCriticalMargin));
}

std::array<double, 5> oscillator_g(double x) {
  std::array<double, 5> g{};
  if (std::abs(x) < 4.0) {
    // Series for g3 and g4, then g_m = 1/m! - x g_{m+2} down to g0 (for 0 < x < 4 the subtraction
    // loses at most a factor 3, at g0 = cos 2).
    g[4] = oscillator_series<4>(x);
    g[3] = oscillator_series<3>(x);
    g[2] = 0.5 - x * g[4];
    g[1] = 1.0 - x * g[3];
    g[0] = 1.0 - x * g[2];
    return g;
  }
  const double s = std::sqrt(std::abs(x));
  g[0] = x > 0 ? std::cos(s) : std::cosh(s);
  g[1] = x > 0 ? std::sin(s) / s : std::sinh(s) / s;
  // g_m = 1/m! - x g_{m+2}; at |x| >= 4 the subtraction loses at most a factor 3.
  const double inv_fact[3] = {1.0, 1.0, 0.5};
  for (int m = 0; m < 3; ++m) g[m + 2] = (inv_fact[m] - g[m]) / x;
  return g;
}

void StepFunctions::compute(double step, const ModeBlocks& blocks) {
  h = step;
  const Eigen::ArrayXd& lambda = blocks.lambda;
  const Eigen::Index n = lambda.size();
  // Sized once (a step's functions are recomputed every step: no allocation after the first).
  ModeFunction* used[] = {&e_half,  &e_full,  &a[1][0], &a[2][0], &a[2][1], &a[3][0],
                          &a[3][1], &a[3][2], &a[4][0], &a[4][1], &a[4][2], &a[4][3],
                          &b[0],    &b[3],    &b[4],    &low[0],  &low[1]};
  for (ModeFunction* f : used) {
    f->alpha.resize(n);
    f->beta.resize(n);
  }
  for (ModeFunction* f : {&b[1], &b[2]}) *f = ModeFunction();  // zero: skipped
  // Per mode, phi_k(h/2 B) (ph) and phi_k(h B) (pf), k = 0..3, for alpha (part 0) and beta
  // (part 1), combined as the method's coefficients.
  for (Eigen::Index i = 0; i < n; ++i) {
    // phi_k(h/2 B) and phi_k(h B) = alpha_k I + beta_k B, k = 0..3 (4 for the series' sake).
    double half[2][5], whole[2][5];
    if (blocks.damped() && blocks.damping(i) != 0.0) {
      damped_oscillator_phi(lambda(i), blocks.damping(i), 0.5 * h, half[0], half[1]);
      damped_oscillator_phi(lambda(i), blocks.damping(i), h, whole[0], whole[1]);
    } else {
      const std::array<double, 5> gh = oscillator_g(lambda(i) * (0.5 * h) * (0.5 * h));
      const std::array<double, 5> gf = oscillator_g(lambda(i) * h * h);
      for (int k = 0; k < 4; ++k) {
        half[0][k] = gh[k];
        half[1][k] = 0.5 * h * gh[k + 1];
        whole[0][k] = gf[k];
        whole[1][k] = h * gf[k + 1];
      }
    }
    for (int part = 0; part < 2; ++part) {
      double ph[4], pf[4];
      for (int k = 0; k < 4; ++k) {
        ph[k] = half[part][k];
        pf[k] = whole[part][k];
      }
      const auto set = [part, i](ModeFunction& f, double v) { (part ? f.beta : f.alpha)(i) = v; };
      set(e_half, ph[0]);
      set(e_full, pf[0]);
      set(a[1][0], 0.5 * ph[1]);
      set(a[2][0], 0.5 * ph[1] - ph[2]);
      set(a[2][1], ph[2]);
      set(a[3][0], pf[1] - 2.0 * pf[2]);
      set(a[3][1], pf[2]);
      set(a[3][2], pf[2]);
      const double a41 = 0.5 * ph[2] - pf[3] + 0.25 * pf[2] - 0.5 * ph[3];
      const double a43 = 0.25 * ph[2] - a41;
      set(a[4][1], a41);
      set(a[4][2], a41);
      set(a[4][3], a43);
      set(a[4][0], 0.5 * ph[1] - 2.0 * a41 - a43);
      set(b[0], pf[1] - 3.0 * pf[2] + 4.0 * pf[3]);
      set(b[3], -pf[2] + 4.0 * pf[3]);
      set(b[4], 4.0 * pf[2] - 8.0 * pf[3]);
      set(low[0], pf[1] - 2.0 * pf[2]);
      set(low[1], 2.0 * pf[2]);
    }
  }
}

}  // namespace beamrail
