#include "core/model/section.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace beamrail {

double rectangle_torsion_constant(double a, double b) {
  if (a < b) std::swap(a, b);
  constexpr double pi = std::numbers::pi;
  // sum_{n odd} tanh(x_n) / n^5 = (31/32) zeta(5) - sum_{n odd} (1 - tanh(x_n)) / n^5; the second
  // sum falls off like exp(-n pi a / b), so a few terms give full precision.
  constexpr double odd_zeta5 = 31.0 / 32.0 * 1.0369277551433699263;
  double tail = 0.0;
  for (int n = 1; n < 60; n += 2) {
    const double x = n * pi * a / (2.0 * b);
    const double term = 2.0 / (std::exp(2.0 * x) + 1.0) / std::pow(n, 5);  // 1 - tanh(x)
    tail += term;
    if (term < 1e-20) break;
  }
  return a * b * b * b / 3.0 * (1.0 - 192.0 / std::pow(pi, 5) * (b / a) * (odd_zeta5 - tail));
}

SectionProperties rectangle_section(double width, double height) {
  SectionProperties s;
  s.area = width * height;
  s.torsion_constant = rectangle_torsion_constant(width, height);
  s.iy = width * height * height * height / 12.0;
  s.iz = height * width * width * width / 12.0;
  s.wy = s.iy / (0.5 * height);
  s.wz = s.iz / (0.5 * width);
  return s;
}

SectionProperties circle_section(double diameter) {
  constexpr double pi = std::numbers::pi;
  SectionProperties s;
  s.area = pi * diameter * diameter / 4.0;
  s.iy = s.iz = pi * std::pow(diameter, 4) / 64.0;
  s.torsion_constant = 2.0 * s.iy;
  s.wy = s.wz = s.iy / (0.5 * diameter);
  return s;
}

SectionProperties tube_section(double outer_diameter, double wall) {
  constexpr double pi = std::numbers::pi;
  const double d = outer_diameter - 2.0 * wall;
  SectionProperties s;
  s.area = pi * (outer_diameter * outer_diameter - d * d) / 4.0;
  s.iy = s.iz = pi * (std::pow(outer_diameter, 4) - std::pow(d, 4)) / 64.0;
  s.torsion_constant = 2.0 * s.iy;
  s.wy = s.wz = s.iy / (0.5 * outer_diameter);
  return s;
}

SectionProperties box_section(double width, double height, double wall) {
  const double wi = width - 2.0 * wall, hi = height - 2.0 * wall;
  SectionProperties s;
  s.area = width * height - wi * hi;
  s.iy = (width * std::pow(height, 3) - wi * std::pow(hi, 3)) / 12.0;
  s.iz = (height * std::pow(width, 3) - hi * std::pow(wi, 3)) / 12.0;
  const double median_area = (width - wall) * (height - wall);
  const double median_perimeter = 2.0 * ((width - wall) + (height - wall));
  s.torsion_constant = 4.0 * median_area * median_area * wall / median_perimeter;
  s.wy = s.iy / (0.5 * height);
  s.wz = s.iz / (0.5 * width);
  return s;
}

}  // namespace beamrail
