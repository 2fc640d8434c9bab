// Cross-section properties of the standard shapes (docs/study_files.md "sections"): area S, torsion
// constant Ix, second moments Iy, Iz and section moduli Wy, Wz. Width runs along local y, height
// along z.
#pragma once

#include "core/model/model.hpp"

namespace beamrail {

// Solid rectangle; torsion constant from Saint-Venant's series.
SectionProperties rectangle_section(double width, double height);
// Solid circle; exact torsion constant pi d^4 / 32.
SectionProperties circle_section(double diameter);
// Circular tube, 0 < wall < outer_diameter / 2; exact torsion constant.
SectionProperties tube_section(double outer_diameter, double wall);
// Rectangular box, 0 < wall < min(width, height) / 2; Bredt's thin-wall torsion constant
// 4 Am^2 t / pm (median area Am, median perimeter pm).
SectionProperties box_section(double width, double height, double wall);

// Saint-Venant torsion constant of a solid a x b rectangle (either order):
// (1/3) a b^3 [1 - (192 b / (pi^5 a)) sum_{n odd} tanh(n pi a / (2 b)) / n^5], a >= b.
double rectangle_torsion_constant(double a, double b);

}  // namespace beamrail
