// A 1 kg tip (inertia 1e-3 kg m^2) on a 1 m cantilever of 10 mm square steel in 10 segments: a
// heavy body that bending pulls in, for the band-limited modal runs' tests.
#pragma once

#include <string>

namespace beamrail::testing {

// The scene with one force on the tip; `force` holds its keys after "body" ("value", "time").
inline std::string heavy_tip_cantilever(const std::string& force) {
  return R"({"materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [{"name": "tip", "mass": 1.0, "inertia": [1e-3, 1e-3, 1e-3], "position": [1, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq",
               "segments": 10}],
    "loads": [{"type": "force", "body": "tip", )" +
         force + "}]}";
}

}  // namespace beamrail::testing
