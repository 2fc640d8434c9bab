// A rotor (2 kg, inertia diag(0.01, 0.01, 0.02) kg m^2) spinning freely at 5 rad/s on a revolute
// joint about z, no gravity, a transient "spin" of 2 s: a mechanism, so verified by default. Its
// closed form is a turn of 5 t about z; its centre stays, so only its orientation can be off.
#pragma once

#include <nlohmann/json.hpp>

namespace beamrail::testing {

// The study (name "rotor") with `integrator` as the transient's integrator block.
inline nlohmann::json spinning_rotor(const nlohmann::json& integrator) {
  nlohmann::json s = nlohmann::json::parse(R"({
    "name": "rotor",
    "scene": {
      "gravity": [0, 0, 0],
      "bodies": [{"name": "rotor", "mass": 2, "inertia": [0.01, 0.01, 0.02],
                  "position": [0, 0, 0], "angular_velocity": [0, 0, 5]}],
      "joints": [{"name": "axle", "type": "revolute", "body1": "ground", "body2": "rotor",
                  "point": [0, 0, 0], "axis": [0, 0, 1]}]
    },
    "analyses": [{"type": "transient", "name": "spin", "t_end": 2.0, "output_step": 0.02}]
  })");
  s["analyses"][0]["integrator"] = integrator;
  return s;
}

}  // namespace beamrail::testing
