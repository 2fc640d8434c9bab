// The reference problem of the speed targets: a steel cantilever 1 m long, 10 mm square section
// (E 2.1e11, G 8.0769e10, density 7850), split into N segments (a chain of N free bodies), with
// a 1 N step tip load at t = 0.
#pragma once

#include <stdexcept>
#include <string>

#include "core/scene/scene_loader.hpp"
#include "tests/support/reference_cantilever.hpp"

namespace beamrail::bench {

inline Model reference_model(int segments) {
  Diagnostics diag;
  const auto json = parse_json(testing::reference_cantilever(segments), "reference", diag);
  std::optional<Model> model;
  if (json) model = load_scene(*json, {"reference", ""}, diag);
  if (!model) throw std::runtime_error(diag.format());
  return *model;
}

}  // namespace beamrail::bench
