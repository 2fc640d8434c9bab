// Regression tests for what fuzzing the study loader found (tests/fuzz/corpus/finding_*.json hold
// the inputs that showed each one; study_fuzz_replay runs them under every build). Each test here
// checks the loader's answer for such an input, not only that it no longer crashes.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "core/scene/json_reader.hpp"
#include "optimizer/study/study.hpp"

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

// A study around a scene whose parts can be replaced one at a time.
nlohmann::json base_study() {
  return nlohmann::json::parse(R"({"name": "range", "scene": {
    "materials": {"steel": {"E": 2.1e11, "G": 8.1e10, "density": 7850}},
    "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [{"name": "tip", "mass": 1, "inertia": [1e-3, 1e-3, 1e-3], "position": [1, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq",
               "segments": 4}],
    "loads": [{"type": "force", "body": "tip", "value": [0, -1, 0]}]},
    "analyses": [{"type": "modal", "modes": 1}]})");
}

std::string problems(const nlohmann::json& study) {
  Diagnostics diag;
  const auto loaded = load_study(study, "finding.json", ".", diag);
  EXPECT_EQ(loaded.has_value(), diag.empty());
  return diag.format();
}

TEST(LoaderFindings, TheRangeBaseStudyLoads) { EXPECT_EQ(problems(base_study()), ""); }

// Finite inputs that overflow once combined used to pass the check and build a model holding
// inf or NaN (met later as a failed or NaN analysis), or were reported as a body "with no mass".
// The fuzzer's contract that a loaded model is finite found them. Found first: a density of
// 1.7e308 (the segment inertias overflow in the 3 x 3 inverse).
TEST(LoaderFindings, HugeDensityIsReportedOncePerEntry) {
  nlohmann::json s = base_study();
  s["scene"]["materials"]["steel"]["density"] = 1.7e308;
  EXPECT_EQ(problems(s),
            "finding.json:/scene/bodies/0: body \"tip\": the inertia cannot be inverted in double "
            "precision (values too large or too small)\n"
            "finding.json:/scene/beams/0: beam \"arm\": the inertia of its interior bodies cannot "
            "be inverted in double precision (values too large or too small)\n");
}

TEST(LoaderFindings, SectionPropertiesOutOfRange) {
  nlohmann::json s = base_study();
  s["scene"]["sections"]["sq"]["width"] = 1e200;
  EXPECT_EQ(problems(s),
            "finding.json:/scene/sections/sq: the section's properties are out of the range of "
            "double precision (S = 1e+198, Ix = 3.33333e+193, Iy = 8.33333e+192, Iz = inf)\n");
  s = base_study();
  s["scene"]["sections"]["sq"] = {{"shape", "circle"}, {"diameter", 1e-100}};
  EXPECT_EQ(problems(s),
            "finding.json:/scene/sections/sq: the section's properties are out of the range of "
            "double precision (S = 7.85398e-201, Ix = 0, Iy = 0, Iz = 0)\n");
}

TEST(LoaderFindings, BodyValuesThatOverflowTogether) {
  nlohmann::json s = base_study();
  s["scene"]["beams"][0]["segments"] = 0;
  s["scene"]["bodies"][0]["mass"] = 1e308;
  s["scene"]["bodies"][0]["position"] = {1e300, 0, 0};
  // m x = 1e608: the centre of mass of the body.
  EXPECT_EQ(problems(s),
            "finding.json:/scene/bodies/0: body \"tip\": the centre of mass is out of the range "
            "of double precision (not finite)\n");
}

TEST(LoaderFindings, ElementStiffnessOrGeometryThatOverflows) {
  nlohmann::json s = base_study();
  s["scene"]["beams"][0]["segments"] = 0;
  s["scene"]["materials"]["steel"]["E"] = 1e308;
  s["scene"]["sections"]["sq"] = {{"shape", "custom"}, {"S", 10}, {"Ix", 1}, {"Iy", 1}, {"Iz", 1}};
  EXPECT_EQ(problems(s),
            "finding.json:/scene/beams/0: beam \"arm\": the axial stiffness E S is out of the "
            "range of double precision (not finite)\n");

  // Points 2e308 apart were reported as coinciding (their distance overflowed to inf).
  s = base_study();
  s["scene"]["beams"][0]["point1"] = {-1e308, 0, 0};
  s["scene"]["beams"][0]["point2"] = {1e308, 0, 0};
  EXPECT_EQ(problems(s),
            "finding.json:/scene/beams/0: the points are too far apart for double precision "
            "(their squared distances overflow)\n");
}

// Gravity of 1e308 on a 10 kg body: its weight overflows. It failed at run time (exit 1, "loads out
// of the range of double precision"); it is bad input (an adversarial review, 2026-12-01).
TEST(LoaderFindings, GravityTimesAMassThatOverflows) {
  nlohmann::json s = base_study();
  s["scene"]["bodies"][0]["mass"] = 10;
  s["scene"]["gravity"] = {0, 0, 1e308};
  const std::string p = problems(s);
  EXPECT_NE(p.find("finding.json:/scene/gravity: gravity times the mass of body \""),
            std::string::npos)
      << p;
  EXPECT_NE(p.find("is out of the range of double precision (not finite)"), std::string::npos) << p;
  s["scene"]["gravity"] = {0, 0, 1e300};  // 1e301 N: finite
  EXPECT_EQ(problems(s), "");
}

TEST(LoaderFindings, LoadPointFarFromItsBody) {
  nlohmann::json s = base_study();
  s["scene"]["bodies"][0]["position"] = {-1e308, 0, 0};
  s["scene"]["beams"][0]["segments"] = 0;
  // Massless: a beam's lumped mass 1e308 m from the body would overflow its inertia first.
  s["scene"]["materials"]["steel"].erase("density");
  s["scene"]["loads"][0]["point"] = {1e308, 0, 0};
  EXPECT_EQ(problems(s),
            "finding.json:/scene/loads/0/point: the distance from the body's centre of mass is out "
            "of the range of double precision (not finite)\n");
}

}  // namespace
}  // namespace beamrail
