// Cross-section properties of the standard shapes (docs/study_files.md "sections"): area S, torsion
// constant Ix, second moments Iy, Iz and section moduli Wy, Wz. Width runs along local y, height
// along z. On the scalar of the model (double, or HyperDual for the design sensitivities; both
// instantiated in section.cpp).
#pragma once

#include "core/model/model.hpp"

namespace beamrail {

// Solid rectangle; torsion constant from Saint-Venant's series.
template <class S>
SectionPropertiesT<S> rectangle_section(S width, S height);
// Solid circle; exact torsion constant pi d^4 / 32.
template <class S>
SectionPropertiesT<S> circle_section(S diameter);
// Circular tube, 0 < wall < outer_diameter / 2; exact torsion constant.
template <class S>
SectionPropertiesT<S> tube_section(S outer_diameter, S wall);
// Rectangular box, 0 < wall < min(width, height) / 2; Bredt's thin-wall torsion constant
// 4 Am^2 t / pm (median area Am, median perimeter pm).
template <class S>
SectionPropertiesT<S> box_section(S width, S height, S wall);

// Saint-Venant torsion constant of a solid a x b rectangle (either order):
// (1/3) a b^3 [1 - (192 b / (pi^5 a)) sum_{n odd} tanh(n pi a / (2 b)) / n^5], a >= b.
template <class S>
S rectangle_torsion_constant(S a, S b);

}  // namespace beamrail
