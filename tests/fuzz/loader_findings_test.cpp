// Regression tests for what fuzzing the study loader found (tests/fuzz/corpus/finding_*.json hold
// the inputs that showed each one; study_fuzz_replay runs them under every build). Each test here
// checks the loader's answer for such an input, not only that it no longer crashes.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/scene/json_reader.hpp"
#include "optimizer/study.hpp"

namespace beamrail {
namespace {

std::optional<Study> load_text(const std::string& text, Diagnostics& diag) {
  const auto document = parse_json(text, "finding.json", diag);
  if (!document) return std::nullopt;
  return load_study(*document, "finding.json", ".", diag);
}

// Splitting a segmented beam read its end bodies through references into the body list while it
// appended the interior bodies to that list (a use after free once the list grew): the interior
// velocities, which blend the end bodies' motion, came from freed memory.
TEST(LoaderFindings, SegmentedBeamInteriorVelocitiesBlendTheEndBodies) {
  const std::string text = R"({"name": "segments", "scene": {
    "materials": {"steel": {"E": 2.1e11, "G": 8.1e10, "density": 7850}},
    "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [{"name": "tip", "mass": 1, "inertia": [1e-3, 1e-3, 1e-3], "position": [1, 0, 0],
                "velocity": [0, 1, 0], "angular_velocity": [0, 0, 2]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq",
               "segments": 4}]},
    "analyses": [{"type": "modal", "modes": 1}]})";
  Diagnostics diag;
  const auto study = load_text(text, diag);
  ASSERT_TRUE(study) << diag.format();
  const Model& m = study->model;
  ASSERT_EQ(m.bodies.size(), 5u);  // ground, tip, arm.node1..3
  for (int k = 1; k <= 3; ++k) {
    const Body& node = m.bodies[1 + k];
    EXPECT_EQ(node.name, "arm.node" + std::to_string(k));
    // s v_tip(x) with v_tip(x) = v + omega x (x - x_tip) = (0, 1 + 2 (s - 1), 0) at x = s = k/4.
    const double s = k / 4.0;
    EXPECT_NEAR(node.velocity.x(), 0.0, 1e-15);
    EXPECT_NEAR(node.velocity.y(), s * (1.0 + 2.0 * (s - 1.0)), 1e-15) << node.name;
    EXPECT_NEAR(node.velocity.z(), 0.0, 1e-15);
    EXPECT_NEAR(node.position.x(), s, 1e-15);
  }
}

}  // namespace
}  // namespace beamrail
