// Builds Models from JSON text for tests; a scene with problems fails the test with the messages.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "core/scene/scene_loader.hpp"

namespace beamrail::testing {

inline Model scene_from_json(const std::string& text) {
  Diagnostics diag;
  const auto json = parse_json(text, "test", diag);
  std::optional<Model> model;
  if (json) model = load_scene(*json, {"test", ""}, diag);
  EXPECT_TRUE(diag.empty()) << diag.format();
  if (!model) return Model{};
  return *model;
}

// The index of the body called `name`; a missing body fails the test (and gives 0).
inline int body_index(const Model& model, const std::string& name) {
  for (size_t i = 0; i < model.bodies.size(); ++i)
    if (model.bodies[i].name == name) return static_cast<int>(i);
  ADD_FAILURE() << "no body " << name;
  return 0;
}

// Issue 17's stiff-hinge pendulum (tests/benchmarks/transient_auto/stiff_hinge_pendulum.json): a
// 1 kg bob on a stiff hinge (a cylindrical rail: a 50 mm axle of 20 mm steel) swinging +-1.5 rad
// under gravity.
inline constexpr const char* kStiffHingePendulum = R"({
    "gravity": [0, 0, -9.81],
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"axle": {"shape": "circle", "diameter": 0.02}},
    "bodies": [{"name": "bob", "mass": 1.0, "inertia": [0.001, 0.001, 0.001],
                "position": [0.05, 0, -0.5], "velocity": [0, 3.0, 0],
                "angular_velocity": [6.0, 0, 0]}],
    "rails": [{"name": "hinge", "type": "cylindrical", "body1": "ground", "body2": "bob",
               "point1": [0, 0, 0], "point2": [0.05, 0, 0], "point3": [0, 1, 0],
               "material": "steel", "section": "axle"}]})";

}  // namespace beamrail::testing
