// The L-frame an adversarial review found (tests/optimizer/large_motion_verification_test.cpp): a
// 1 m steel arm of 5 segments from the ground to a 1 kg tip, a 0.6 m leg of 3 segments down to a
// 2 kg foot, 2 N down on the tip, the tip thrown at speed x (0, 2, 1) m/s; a transient "swing" of
// 0.5 s. Its large motion makes auto relinearize, so it is verified by default.
#pragma once

#include <nlohmann/json.hpp>

namespace beamrail::testing {

// The study (name "l_frame") with `integrator` as the transient's integrator block.
inline nlohmann::json l_frame(double speed, const nlohmann::json& integrator) {
  nlohmann::json s = nlohmann::json::parse(R"({
    "name": "l_frame",
    "scene": {
      "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
      "sections": {"bar": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
      "bodies": [{"name": "tip", "mass": 1, "inertia": [1e-5, 1e-5, 1e-5], "position": [1, 0, 0]},
                 {"name": "foot", "mass": 2, "inertia": [1e-4, 1e-4, 1e-4],
                  "position": [1, -0.6, 0]}],
      "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
                 "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "bar",
                 "segments": 5},
                {"name": "leg", "body1": "tip", "body2": "foot", "point1": [1, 0, 0],
                 "point2": [1, -0.6, 0], "point3": [2, 0, 0], "material": "steel",
                 "section": "bar", "segments": 3}],
      "loads": [{"type": "force", "body": "tip", "value": [0, 0, -2]}]
    },
    "analyses": [{"type": "transient", "name": "swing", "t_end": 0.5, "output_step": 0.005}]
  })");
  s["scene"]["bodies"][0]["velocity"] = {0.0, 2.0 * speed, speed};
  s["analyses"][0]["integrator"] = integrator;
  return s;
}

}  // namespace beamrail::testing
