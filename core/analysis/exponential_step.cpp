#include "core/analysis/exponential_step.hpp"

#include <cmath>

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

}  // namespace

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

void StepFunctions::compute(double step, const Eigen::ArrayXd& lambda) {
  h = step;
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
    const std::array<double, 5> gh = oscillator_g(lambda(i) * (0.5 * h) * (0.5 * h));
    const std::array<double, 5> gf = oscillator_g(lambda(i) * h * h);
    for (int part = 0; part < 2; ++part) {
      double ph[4], pf[4];
      for (int k = 0; k < 4; ++k) {
        ph[k] = part ? 0.5 * h * gh[k + 1] : gh[k];
        pf[k] = part ? h * gf[k + 1] : gf[k];
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
