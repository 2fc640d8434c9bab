// Issue 17's point-mass tip: a 3 kg body of rotary inertia 1e-6 kg m^2 on a massless 1 m steel
// cantilever of square section `width` along x, under a step load `load` [N] in -y on the tip at
// t = 0: its bending beside a rotary mode of some 1e5 rad/s. Scene JSON text.
#pragma once

#include <string>

namespace beamrail::testing {

inline std::string point_mass_tip(double width, double load) {
  return R"({"materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"sq": {"shape": "rectangle", "width": )" +
         std::to_string(width) + R"(, "height": )" + std::to_string(width) + R"(}},
    "bodies": [{"name": "tip", "mass": 3.0, "inertia": [1e-6, 1e-6, 1e-6], "position": [1, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq"}],
    "loads": [{"type": "force", "body": "tip", "value": [0, )" +
         std::to_string(-load) + R"(, 0], "time": {"type": "step", "at": 0.0}}]})";
}

}  // namespace beamrail::testing
