#include "core/model/section.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/model/hyper_dual.hpp"

namespace beamrail {

template <class S>
S rectangle_torsion_constant(S a, S b) {
  using std::exp;
  if (a < b) std::swap(a, b);
  constexpr double pi = std::numbers::pi;
  // sum_{n odd} tanh(x_n) / n^5 = (31/32) zeta(5) - sum_{n odd} (1 - tanh(x_n)) / n^5; the second
  // sum falls off like exp(-n pi a / b), so a few terms give full precision.
  constexpr double odd_zeta5 = 31.0 / 32.0 * 1.0369277551433699263;
  S tail = 0.0;
  for (int n = 1; n < 60; n += 2) {
    const S x = n * pi * a / (2.0 * b);
    // 1 - tanh(x) = 2 e^-2x / (1 + e^-2x): no overflow for a thin strip (x > 355), whose
    // exp(2x) would be infinite (harmless for doubles, NaN derivatives for dual numbers).
    const S e = exp(-2.0 * x);
    const S term = 2.0 * e / (1.0 + e) / std::pow(n, 5);
    tail += term;
    if (term < 1e-20) break;
  }
  return a * b * b * b / 3.0 * (1.0 - 192.0 / std::pow(pi, 5) * (b / a) * (odd_zeta5 - tail));
}

template <class S>
SectionPropertiesT<S> rectangle_section(S width, S height) {
  SectionPropertiesT<S> s;
  s.area = width * height;
  s.torsion_constant = rectangle_torsion_constant(width, height);
  s.iy = width * height * height * height / 12.0;
  s.iz = height * width * width * width / 12.0;
  s.wy = s.iy / (0.5 * height);
  s.wz = s.iz / (0.5 * width);
  return s;
}

template <class S>
SectionPropertiesT<S> circle_section(S diameter) {
  constexpr double pi = std::numbers::pi;
  SectionPropertiesT<S> s;
  s.area = pi * diameter * diameter / 4.0;
  s.iy = s.iz = pi * (diameter * diameter) * (diameter * diameter) / 64.0;
  s.torsion_constant = 2.0 * s.iy;
  s.wy = s.wz = s.iy / (0.5 * diameter);
  return s;
}

template <class S>
SectionPropertiesT<S> tube_section(S outer_diameter, S wall) {
  constexpr double pi = std::numbers::pi;
  const S d = outer_diameter - 2.0 * wall;
  const S o2 = outer_diameter * outer_diameter, d2 = d * d;
  SectionPropertiesT<S> s;
  s.area = pi * (o2 - d2) / 4.0;
  s.iy = s.iz = pi * (o2 * o2 - d2 * d2) / 64.0;
  s.torsion_constant = 2.0 * s.iy;
  s.wy = s.wz = s.iy / (0.5 * outer_diameter);
  return s;
}

template <class S>
SectionPropertiesT<S> box_section(S width, S height, S wall) {
  const S wi = width - 2.0 * wall, hi = height - 2.0 * wall;
  const auto cube = [](const S& x) { return x * x * x; };
  SectionPropertiesT<S> s;
  s.area = width * height - wi * hi;
  s.iy = (width * cube(height) - wi * cube(hi)) / 12.0;
  s.iz = (height * cube(width) - hi * cube(wi)) / 12.0;
  const S median_area = (width - wall) * (height - wall);
  const S median_perimeter = 2.0 * ((width - wall) + (height - wall));
  s.torsion_constant = 4.0 * median_area * median_area * wall / median_perimeter;
  s.wy = s.iy / (0.5 * height);
  s.wz = s.iz / (0.5 * width);
  return s;
}

#define BEAMRAIL_SECTIONS(S)                              \
  template S rectangle_torsion_constant(S, S);            \
  template SectionPropertiesT<S> rectangle_section(S, S); \
  template SectionPropertiesT<S> circle_section(S);       \
  template SectionPropertiesT<S> tube_section(S, S);      \
  template SectionPropertiesT<S> box_section(S, S, S);
BEAMRAIL_SECTIONS(double)
BEAMRAIL_SECTIONS(HyperDual)
#undef BEAMRAIL_SECTIONS

}  // namespace beamrail
