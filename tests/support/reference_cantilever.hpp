// The reference cantilever of the speed targets: steel (E 2.1e11, G 8.0769e10, density 7850),
// square section `width` (default 10 mm), `length` long (default 1 m) along x, split into
// `segments` segments (a chain of free bodies), with a 1 N step load in -y on its tip body at
// t = 0: every bending, axial and rotary mode of the chain is excited. Scene JSON text.
#pragma once

#include <string>

namespace beamrail::testing {

inline std::string reference_cantilever(int segments, double width = 0.01, double length = 1.0) {
  const std::string w = std::to_string(width), l = std::to_string(length);
  return R"({"materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"sq": {"shape": "rectangle", "width": )" +
         w + R"(, "height": )" + w + R"(}},
    "bodies": [{"name": "tip", "position": [)" +
         l + R"(, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [)" +
         l + R"(, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq",
               "segments": )" +
         std::to_string(segments) + R"(}],
    "loads": [{"type": "force", "body": "tip", "value": [0, -1, 0],
               "time": {"type": "step", "at": 0.0}}]})";
}

}  // namespace beamrail::testing
