// Issue 17's point-mass tip: a 3 kg body of rotary inertia 1e-6 kg m^2 on a 1 m steel cantilever
// of square section `width` along x, under a step load `load` [N] in -y on the tip at t = 0: its
// bending beside a rotary mode of some 1e5 rad/s. Scene JSON text. Optionally with beam damping
// [s], a load component `load_z` [N] along z, and the steel's density (0: a massless beam).
#pragma once

#include <string>

namespace beamrail::testing {

inline std::string point_mass_tip(double width, double load, double damping = 0.0,
                                  double load_z = 0.0, double density = 0.0) {
  const std::string mass = density > 0.0 ? R"(, "density": )" + std::to_string(density) : "";
  const std::string damped = damping > 0.0 ? R"("damping": )" + std::to_string(damping) + ", " : "";
  return R"({"materials": {"steel": {"E": 2.1e11, "G": 8.0769e10)" + mass + R"(}},
    "sections": {"sq": {"shape": "rectangle", "width": )" +
         std::to_string(width) + R"(, "height": )" + std::to_string(width) + R"(}},
    "bodies": [{"name": "tip", "mass": 3.0, "inertia": [1e-6, 1e-6, 1e-6], "position": [1, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", )" +
         damped + R"("section": "sq"}],
    "loads": [{"type": "force", "body": "tip", "value": [0, )" +
         std::to_string(-load) + ", " + std::to_string(load_z) +
         R"(], "time": {"type": "step", "at": 0.0}}]})";
}

}  // namespace beamrail::testing
