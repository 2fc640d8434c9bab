// Frequency responses that follow a mode through a design study (optimizer/run/responses.hpp): by
// shape ("track": the mode with the largest MAC against the study's own design's mode), by
// dominant direction ("dominant"), and by number, on a tip body whose two bending modes cross
// when the section's width passes its height. Each is compared with the closed form of the
// bending mode it should follow; a tracked mode that no computed mode resembles is a warning.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "core/scene/json_reader.hpp"
#include "optimizer/run/designs.hpp"
#include "tests/support/closed_forms.hpp"

namespace beamrail {
namespace {

constexpr double kE = 2.1e11, kL = 1.0, kHeight = 0.01, kMass = 2.0, kJ = 1e-6;

// A 2 kg tip on a massless 1 m steel cantilever along x of a width x 10 mm rectangle (width along
// global y): bending in y is stiffened by width^3, bending in z by width. At the study's own width
// (8 mm) mode 1 bends in y.
std::string study_text(int modes) {
  return R"({"name": "tracking", "scene": {
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"r": {"shape": "rectangle", "width": 0.008, "height": 0.01}},
    "bodies": [{"name": "tip", "mass": 2.0, "inertia": [1e-6, 1e-6, 1e-6], "position": [1, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "r"}]},
  "analyses": [{"type": "modal", "about": "initial", "modes": )" +
         std::to_string(modes) + R"(}],
  "responses": {
    "f1": {"quantity": "frequency", "mode": 1},
    "f1_tracked": {"quantity": "frequency", "mode": 1, "track": true},
    "f_y": {"quantity": "frequency", "dominant": "y"},
    "f_z": {"quantity": "frequency", "dominant": "z"}},
  "study": {"type": "sweep", "sampling": "list", "variables": [
    {"name": "width", "pointer": "/scene/sections/r/width"}],
    "rows": [[0.008], [0.0095], [0.0105], [0.012]]}})";
}

// The lowest bending frequency of the tip with bending stiffness E I [Hz].
double bending_hz(double i) {
  return std::sqrt(testing::bending_pair(kE * i, kL, kMass, kJ, 0.0)[0]) / (2 * std::numbers::pi);
}

std::optional<Study> load(const std::string& text, Diagnostics& diag) {
  const auto document = parse_json(text, "tracking.json", diag);
  if (!document) return std::nullopt;
  return load_study(*document, "tracking.json", ".", diag);
}

TEST(ModeTracking, TrackedModeFollowsItsShapeThroughACrossing) {
  Diagnostics diag;
  const auto study = load(study_text(2), diag);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator evaluator(*study);
  ASSERT_EQ(evaluator.setup_failure(), "");
  bool crossed = false;
  for (double w : {0.008, 0.0095, 0.0105, 0.012}) {
    const DesignOutcome o = evaluator.evaluate({w});
    ASSERT_EQ(o.status, Status::kOk) << o.message;
    EXPECT_EQ(o.warnings, 0) << o.message;
    const double fy = bending_hz(kHeight * w * w * w / 12),
                 fz = bending_hz(w * std::pow(kHeight, 3) / 12);
    const double f1 = o.responses[0], tracked = o.responses[1];
    std::printf("width %.4f: f1 %.6f Hz, tracked %.6f Hz; closed forms: y %.6f Hz, z %.6f Hz\n", w,
                f1, tracked, fy, fz);
    crossed = crossed || fz < fy;
    EXPECT_NEAR(f1 / std::min(fy, fz), 1.0, 1e-9);
    EXPECT_NEAR(tracked / fy, 1.0, 1e-9);  // the y bending mode, also where it is mode 2
    EXPECT_NEAR(o.responses[2] / fy, 1.0, 1e-9);
    EXPECT_NEAR(o.responses[3] / fz, 1.0, 1e-9);
  }
  EXPECT_TRUE(crossed);  // the sweep does cross
}

// With one mode computed, the y bending mode is missing once the z mode is the lower: the tracked
// response warns (and an optimization counts the design infeasible), as does the dominant-y one.
TEST(ModeTracking, TrackedModeMissingFromTheComputedModesIsAWarning) {
  Diagnostics diag;
  const auto study = load(study_text(1), diag);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator evaluator(*study);
  const DesignOutcome before = evaluator.evaluate({0.0095});
  ASSERT_EQ(before.status, Status::kOk) << before.message;
  EXPECT_TRUE(std::isnan(before.responses[3]));  // no z-dominant mode among those computed
  EXPECT_NE(before.message.find("dominant direction z: compute more modes"), std::string::npos)
      << before.message;
  const DesignOutcome after = evaluator.evaluate({0.012});
  ASSERT_EQ(after.status, Status::kOk) << after.message;
  EXPECT_NE(after.message.find("\"f1_tracked\" tracks mode 1 of the study's design, but no "
                               "computed mode resembles it (best MAC 0.000)"),
            std::string::npos)
      << after.message;
}

// Each refusal at its pointer.
void expect_refused(const Json& doc, const std::string& pointer, const std::string& message) {
  Diagnostics diag;
  EXPECT_FALSE(load_study(doc, "tracking.json", ".", diag));
  bool found = false;
  for (const Diagnostic& d : diag.items())
    found = found || (d.pointer == pointer && d.message.find(message) != std::string::npos);
  EXPECT_TRUE(found) << "expected at " << pointer << ": " << message << "\ngot:\n" << diag.format();
}

TEST(ModeTracking, ContradictoryChoicesOfAModeAreRefusedAtTheirPointers) {
  Json doc = Json::parse(study_text(2));
  doc["responses"]["f_y"]["mode"] = 2;
  expect_refused(doc, "/responses/f_y/dominant", "give either \"mode\" or \"dominant\"");
  doc = Json::parse(study_text(2));
  doc["responses"]["f_y"]["track"] = true;
  expect_refused(doc, "/responses/f_y/track", "is not tracked by shape");
  doc = Json::parse(study_text(2));
  doc["responses"]["f_y"]["dominant"] = "w";
  expect_refused(doc, "/responses/f_y/dominant", "");
  doc = Json::parse(study_text(2));
  doc["responses"]["f1_tracked"]["track"] = 1;
  expect_refused(doc, "/responses/f1_tracked/track", "");
}

}  // namespace
}  // namespace beamrail
