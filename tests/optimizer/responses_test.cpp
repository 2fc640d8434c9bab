// Responses at the library level: expressions over other responses (muparser) in dependency order
// whatever their names, NaN from responses not computed, a warning for a non-finite result of
// finite inputs; masses of subsets of bodies and elements; affine design-variable links; and the
// bad input of each, with its JSON pointer.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "optimizer/run/designs.hpp"
#include "optimizer/run/evaluation.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {
namespace {

// A massless steel cantilever (1 m, 10 mm square) with a 2 kg tip under a 1 N load along (0, 3, 4)
// / 5, a segmented 5 kg-per-metre side arm, a rail with a carriage.
Json base() {
  return Json::parse(R"({
    "name": "responses",
    "scene": {
      "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}, "dense": {"E": 2.1e11, "G": 8.0769e10, "density": 5e4}},
      "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
      "bodies": [{"name": "tip", "mass": 2.0, "inertia": [1e-4, 1e-4, 1e-4], "position": [1, 0, 0]},
                 {"name": "carriage", "mass": 0.5, "inertia": [1e-4, 1e-4, 1e-4], "position": [0, 0, 1]}],
      "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
                 "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq"},
                {"name": "side", "body1": "ground", "body2": "tip", "point1": [1, -1, 0],
                 "point2": [1, 0, 0], "point3": [2, -1, 0], "material": "dense", "section": "sq",
                 "segments": 4},
                {"name": "post", "body1": "ground", "body2": "carriage", "point1": [0, 0, 0],
                 "point2": [0, 0, 1], "point3": [1, 0, 0], "material": "steel", "section": "sq"}],
      "rails": [{"name": "guide", "type": "prismatic", "body1": "ground", "body2": "carriage",
                 "point1": [0, 0, 0.5], "point2": [0, 0, 1], "point3": [1, 0, 0.5],
                 "material": "dense", "section": "sq"}],
      "loads": [{"type": "force", "body": "tip", "value": [0, 0.6, 0.8]}]
    },
    "analyses": [{"type": "static"}],
    "responses": {
      "dy": {"quantity": "displacement", "body": "tip", "direction": [0, 1, 0]},
      "dz": {"quantity": "displacement", "body": "tip", "direction": [0, 0, 1]}
    }
  })");
}

std::optional<Study> load(const Json& doc, Diagnostics& diag) {
  return load_study(doc, "r.json", ".", diag);
}

// The responses of one evaluation, by name.
std::map<std::string, double> evaluate_named(const Json& doc, Evaluation* out = nullptr) {
  Diagnostics diag;
  const auto study = load(doc, diag);
  EXPECT_TRUE(study) << diag.format();
  if (!study) return {};
  const Evaluation ev = evaluate(*study, study->model, {});
  std::map<std::string, double> values;
  for (size_t k = 0; k < study->responses.size(); ++k)
    values[study->responses[k].name] = ev.responses[k];
  if (out) *out = ev;
  return values;
}

TEST(Responses, ExpressionsOverOtherResponsesInDependencyOrder) {
  Json doc = base();
  // Named so that the readers meet them before what they read ("a_" < "d" < "z_").
  doc["responses"]["a_worst"] = {{"quantity", "expression"},
                                 {"expression", "max(abs(dy), abs(dz), z_mag / 2)"}};
  doc["responses"]["z_mag"] = {{"quantity", "expression"}, {"expression", "sqrt(dy^2 + dz^2)"}};
  // Comparisons are no assignments.
  doc["responses"]["tests"] = {
      {"quantity", "expression"},
      {"expression", "(dy >= dz) + 2 * (dy != dz) + 4 * (dy == dy) + 8 * (dy <= dz)"}};
  Evaluation ev;
  const auto v = evaluate_named(doc, &ev);
  ASSERT_EQ(ev.status, Status::kOk) << ev.message;
  EXPECT_NE(v.at("dy"), 0.0);
  EXPECT_EQ(v.at("z_mag"), std::sqrt(v.at("dy") * v.at("dy") + v.at("dz") * v.at("dz")));
  EXPECT_EQ(v.at("a_worst"),
            std::max({std::abs(v.at("dy")), std::abs(v.at("dz")), v.at("z_mag") / 2}));
  const double dy = v.at("dy"), dz = v.at("dz");
  EXPECT_EQ(v.at("tests"), (dy >= dz) + 2 * (dy != dz) + 4 + 8 * (dy <= dz));
  EXPECT_TRUE(ev.warnings.empty());
}

TEST(Responses, AnExpressionOfAResponseNotComputedIsNaNAndOneNotFiniteWarns) {
  Json doc = base();
  doc["responses"]["inverse"] = {{"quantity", "expression"}, {"expression", "1 / (dy - dy)"}};
  Evaluation ev;
  auto v = evaluate_named(doc, &ev);
  EXPECT_TRUE(std::isinf(v.at("inverse")));
  ASSERT_EQ(ev.warnings.size(), 1u);
  EXPECT_NE(ev.warnings[0].find("expression \"inverse\" is inf where its inputs are finite (dy = "),
            std::string::npos)
      << ev.warnings[0];
  // The static analysis fails (the load exceeds double precision): dy is NaN, and so is the
  // expression, without a warning of its own.
  doc["scene"]["loads"][0]["value"] = {0, 1e300, 1e300};
  v = evaluate_named(doc, &ev);
  EXPECT_EQ(ev.status, Status::kFailed);
  EXPECT_TRUE(std::isnan(v.at("dy")));
  EXPECT_TRUE(std::isnan(v.at("inverse")));
  for (const std::string& w : ev.warnings) EXPECT_EQ(w.find("expression"), std::string::npos) << w;
}

TEST(Responses, MassOfSubsetsOfBodiesAndElements) {
  Json doc = base();
  doc["analyses"] = {{{"type", "modal"}, {"modes", 1}}};
  doc["responses"] = {
      {"all", {{"quantity", "mass"}}},
      {"tip", {{"quantity", "mass"}, {"bodies", {"tip"}}}},
      {"side", {{"quantity", "mass"}, {"elements", {"side"}}}},
      {"guide", {{"quantity", "mass"}, {"elements", {"guide"}}}},
      {"both",
       {{"quantity", "mass"}, {"bodies", {"carriage", "tip"}}, {"elements", {"side", "arm"}}}}};
  const auto v = evaluate_named(doc);
  const double side = 5e4 * 1e-4 * 1.0, guide = 5e4 * 1e-4 * 0.5;  // rho S l
  EXPECT_DOUBLE_EQ(v.at("tip"), 2.0);
  EXPECT_DOUBLE_EQ(v.at("side"), side);  // all four segments of the scene beam
  EXPECT_DOUBLE_EQ(v.at("guide"), guide);
  EXPECT_DOUBLE_EQ(v.at("both"), 2.5 + side);  // "arm" has no density
  EXPECT_DOUBLE_EQ(v.at("all"), 2.5 + side + guide);
}

TEST(Responses, AffineLinksWriteFactorTimesValuePlusOffset) {
  Json doc = base();
  doc["study"] = Json::parse(R"({"type": "sweep", "sampling": "list", "rows": [[0.3]],
      "variables": [{"name": "w", "pointer": ["/scene/bodies/0/mass", "/scene/sections/sq/width"],
                     "factors": [40, 0.1], "offsets": [1.5, 0.002]}]})");
  Diagnostics diag;
  const auto study = load(doc, diag);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator designs(*study);
  const Json d = designs.document({0.3});
  EXPECT_DOUBLE_EQ(d["scene"]["bodies"][0]["mass"].get<double>(), 40 * 0.3 + 1.5);
  EXPECT_DOUBLE_EQ(d["scene"]["sections"]["sq"]["width"].get<double>(), 0.1 * 0.3 + 0.002);
}

// Each problem once, at its pointer.
void expect_refused(const Json& doc, const std::string& pointer, const std::string& message) {
  Diagnostics diag;
  EXPECT_FALSE(load(doc, diag));
  bool found = false;
  for (const Diagnostic& d : diag.items())
    found = found || (d.pointer == pointer && d.message.find(message) != std::string::npos);
  EXPECT_TRUE(found) << "expected at " << pointer << ": " << message << "\ngot:\n" << diag.format();
}

TEST(Responses, BadExpressionsMassesAndLinksAreRefusedWithTheirPointers) {
  Json doc = base();
  doc["responses"]["e"] = {{"quantity", "expression"}, {"expression", "sqrt(dy^2 +"}};
  expect_refused(doc, "/responses/e/expression", "Unexpected end of expression");
  doc["responses"]["e"]["expression"] = "dy + dx";
  expect_refused(doc, "/responses/e/expression", "\"dx\" is no response of the study");
  doc["responses"]["e"]["expression"] = "e + 1";
  expect_refused(doc, "/responses/e/expression", "reads its own response \"e\"");
  // An assignment wrote into the response it named ("dy = dy * 100": dy reported 100 times its
  // value, status ok; an adversarial review, 2026-12-01), and several results gave the last.
  doc["responses"]["e"]["expression"] = "dy = dy * 100";
  expect_refused(doc, "/responses/e/expression",
                 "an assignment (\"=\") would write into a response");
  doc["responses"]["e"]["expression"] = "dy, 2 * dy";
  expect_refused(doc, "/responses/e/expression", "2 results separated by commas");
  doc["responses"]["e"]["expression"] = "f + 1";
  doc["responses"]["f"] = {{"quantity", "expression"}, {"expression", "2 * e"}};
  expect_refused(doc, "/responses/f/expression", "a cycle");
  doc = base();
  doc["responses"]["m"] = {{"quantity", "mass"}, {"bodies", {"tip", "nobody"}}};
  expect_refused(doc, "/responses/m/bodies/1", "unknown body \"nobody\"");
  doc["responses"]["m"] = {{"quantity", "mass"}, {"elements", {"arm.seg1"}}};
  expect_refused(doc, "/responses/m/elements/0", "unknown beam or rail \"arm.seg1\"");
  doc["responses"]["m"] = {{"quantity", "mass"}, {"bodies", Json::array()}};
  expect_refused(doc, "/responses/m/bodies", "expected a non-empty array of names");
  doc = base();
  doc["study"] = Json::parse(R"({"type": "sweep", "sampling": "list", "rows": [[0.3]],
      "variables": [{"name": "w", "pointer": ["/scene/bodies/0/mass"], "offsets": [1, 2]}]})");
  expect_refused(doc, "/study/variables/0/offsets", "");
}

// An expression that reads a response whose own errors kept it out is not reported again as
// reading "no response of the study" (it was, beside a scene error that dropped the response).
TEST(Responses, AnExpressionOfARefusedResponseAddsNoSecondError) {
  Json doc = base();
  doc["responses"]["dy"]["body"] = "nobody";
  doc["responses"]["e"] = {{"quantity", "expression"}, {"expression", "2 * dy"}};
  Diagnostics diag;
  EXPECT_FALSE(load(doc, diag));
  int errors = 0;
  for (const Diagnostic& d : diag.items()) {
    ++errors;
    EXPECT_EQ(d.message.find("is no response of the study"), std::string::npos) << diag.format();
  }
  EXPECT_EQ(errors, 1) << diag.format();
  doc["responses"]["e"]["expression"] = "2 * dx";  // a name no response has: still an error
  expect_refused(doc, "/responses/e/expression", "\"dx\" is no response of the study");
}

}  // namespace
}  // namespace beamrail
