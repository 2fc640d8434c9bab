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

}  // namespace beamrail::testing
