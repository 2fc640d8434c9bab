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

ModeFunction combine(std::initializer_list<std::pair<double, const ModeFunction*>> terms) {
  ModeFunction r(terms.begin()->second->alpha.size());
  for (const auto& [s, f] : terms) r.add(s, *f);
  return r;
}

void StepFunctions::compute(double step, const Eigen::ArrayXd& lambda) {
  h = step;
  const Eigen::Index n = lambda.size();
  ModeFunction phi_h[4], phi_f[4];  // phi_k(h/2 B), phi_k(h B)
  for (auto& f : phi_h) f = ModeFunction(n);
  for (auto& f : phi_f) f = ModeFunction(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (int half = 0; half < 2; ++half) {
      const double tau = half ? 0.5 * h : h;
      const std::array<double, 5> g = oscillator_g(lambda(i) * tau * tau);
      ModeFunction* phi = half ? phi_h : phi_f;
      for (int k = 0; k < 4; ++k) {
        phi[k].alpha(i) = g[k];
        phi[k].beta(i) = tau * g[k + 1];
      }
    }
  }
  e_half = phi_h[0];
  e_full = phi_f[0];
  for (auto& row : a)
    for (auto& f : row) f = ModeFunction();
  a[1][0] = combine({{0.5, &phi_h[1]}});
  a[2][0] = combine({{0.5, &phi_h[1]}, {-1.0, &phi_h[2]}});
  a[2][1] = phi_h[2];
  a[3][0] = combine({{1.0, &phi_f[1]}, {-2.0, &phi_f[2]}});
  a[3][1] = phi_f[2];
  a[3][2] = phi_f[2];
  a[4][1] = combine({{0.5, &phi_h[2]}, {-1.0, &phi_f[3]}, {0.25, &phi_f[2]}, {-0.5, &phi_h[3]}});
  a[4][2] = a[4][1];
  a[4][3] = combine({{0.25, &phi_h[2]}, {-1.0, &a[4][1]}});
  a[4][0] = combine({{0.5, &phi_h[1]}, {-2.0, &a[4][1]}, {-1.0, &a[4][3]}});
  b[0] = combine({{1.0, &phi_f[1]}, {-3.0, &phi_f[2]}, {4.0, &phi_f[3]}});
  b[1] = b[2] = ModeFunction();
  b[3] = combine({{-1.0, &phi_f[2]}, {4.0, &phi_f[3]}});
  b[4] = combine({{4.0, &phi_f[2]}, {-8.0, &phi_f[3]}});
  low[0] = combine({{1.0, &phi_f[1]}, {-2.0, &phi_f[2]}});
  low[1] = combine({{2.0, &phi_f[2]}});
}

}  // namespace beamrail
