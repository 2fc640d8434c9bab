// The reference problem of the speed targets: a steel cantilever 1 m long, 10 mm square section
// (E 2.1e11, G 8.0769e10, density 7850), split into N segments (a chain of N free bodies), with
// a 1 N step tip load at t = 0.
#pragma once

#include <stdexcept>
#include <string>

#include "core/scene/scene_loader.hpp"

namespace beamrail::bench {

inline std::string reference_scene(int segments) {
  return R"({"materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"sq10": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [{"name": "tip", "position": [1, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq10",
               "segments": )" +
         std::to_string(segments) + R"(}],
    "loads": [{"type": "force", "body": "tip", "value": [0, -1, 0],
               "time": {"type": "step", "at": 0.0}}]})";
}

inline Model reference_model(int segments) {
  Diagnostics diag;
  const auto json = parse_json(reference_scene(segments), "reference", diag);
  std::optional<Model> model;
  if (json) model = load_scene(*json, {"reference", ""}, diag);
  if (!model) throw std::runtime_error(diag.format());
  return *model;
}

}  // namespace beamrail::bench
