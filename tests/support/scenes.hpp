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

}  // namespace beamrail::testing
