// Design sensitivities (optimizer/run/sensitivities.hpp, core/analysis/sensitivity.hpp):
//  - closed forms: a tip cantilever's deflection F L^3 / (3 E I) and frequency against the load,
//    E and the section; an Euler column's buckling factor, proportional to E; the derivatives of a
//    repeated frequency (a square section) as the width grows, 3:1;
//  - a frame with load cases, a payload on struts, a modal analysis about a loaded equilibrium and
//    a buckling analysis about another: every response kind (mass and a subset, displacement,
//    rotation, element force, stress, frequency, buckling factor, an expression) against every
//    variable kind (section dimensions, E, density, an attachment point, body mass, inertia and
//    position, load values) agrees with extrapolated central differences of whole evaluations;
//  - what has no exact derivative says so.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <utility>

#include "core/scene/json_reader.hpp"
#include "optimizer/run/designs.hpp"
#include "tests/support/closed_forms.hpp"
#include "tests/support/design_differences.hpp"

namespace beamrail {
namespace {

std::optional<Study> load(const std::string& text, Diagnostics& diag) {
  const auto document = parse_json(text, "sensitivities.json", diag);
  if (!document) return std::nullopt;
  return load_study(*document, "sensitivities.json", ".", diag);
}

struct Result {
  DesignOutcome outcome;
  ResponseSensitivities s;
};

Result at(const DesignEvaluator& evaluator, const std::vector<double>& x) {
  Result r;
  r.outcome = evaluator.evaluate(x, &r.s);
  EXPECT_EQ(r.outcome.status, Status::kOk) << r.outcome.message;
  EXPECT_TRUE(r.s.ok) << r.s.message;
  return r;
}

std::vector<double> values(const Study& study) {
  std::vector<double> x;
  for (const DesignVariable& v : study.design->variables) x.push_back(v.value);
  return x;
}

// A 2 kg tip (rotary inertia 1e-6) on a massless 1 m steel cantilever of a w x 10 mm rectangle
// along x, a 3 N tip load along -y.
const char* kCantilever = R"({"name": "tip", "scene": {
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"r": {"shape": "rectangle", "width": 0.012, "height": 0.01}},
    "bodies": [{"name": "tip", "mass": 2.0, "inertia": [1e-6, 1e-6, 1e-6], "position": [1, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "r"}],
    "loads": [{"type": "force", "body": "tip", "value": [0, -3, 0]}]},
  "analyses": [{"type": "static"}, {"type": "modal", "modes": 2, "about": "initial"}],
  "responses": {
    "dy": {"quantity": "displacement", "body": "tip", "direction": [0, -1, 0]},
    "f1": {"quantity": "frequency", "mode": 1},
    "f2": {"quantity": "frequency", "mode": 2}},
  "study": {"type": "sensitivity", "variables": [
    {"name": "w", "pointer": "/scene/sections/r/width"},
    {"name": "E", "pointer": "/scene/materials/steel/E"},
    {"name": "F", "pointer": "/scene/loads/0/value/1", "factors": [-1]}]}})";

TEST(Sensitivities, TipCantileverMatchesClosedForms) {
  Diagnostics diag;
  const auto study = load(kCantilever, diag);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator evaluator(*study);
  const Result r = at(evaluator, values(*study));
  ASSERT_TRUE(r.s.ok);
  const double w = 0.012, h = 0.01, e = 2.1e11, f = 3.0, l = 1.0, m = 2.0, j = 1e-6;
  const double iz = h * w * w * w / 12, iy = w * h * h * h / 12;  // bending in y, in z
  // Small-deflection static: dy = F L^3 / (3 E Iz); the geometrically nonlinear answer differs by
  // ~(dy/L)^2 = 1e-6.
  const double dy = f * l * l * l / (3 * e * iz);
  const double ddy[3] = {-3 * dy / w, -dy / e, dy / f};
  // Mode 1 bends in z (Iy < Iz), mode 2 in y: lambda proportional to E I.
  const auto hz = [&](double ei) {
    return std::sqrt(testing::bending_pair(ei, l, m, j, 0.0)[0]) / (2 * std::numbers::pi);
  };
  const double f1 = hz(e * iy), f2 = hz(e * iz);
  const double df1[3] = {f1 / (2 * w), f1 / (2 * e), 0.0};
  const double df2[3] = {3 * f2 / (2 * w), f2 / (2 * e), 0.0};
  for (int v = 0; v < 3; ++v) {
    std::printf(
        "variable %d: d dy %.10e (closed form %.10e), d f1 %.10e (%.10e), d f2 %.10e "
        "(%.10e)\n",
        v, r.s.jacobian(0, v), ddy[v], r.s.jacobian(1, v), df1[v], r.s.jacobian(2, v), df2[v]);
    EXPECT_NEAR(r.s.jacobian(0, v) / ddy[v], 1.0, 1e-5);  // the nonlinearity, not the method
    // The frequencies about the initial state are exactly those of the closed form, and their
    // derivatives are exact (automatic differentiation through the scene build and the kernels):
    // rounding only (differences of the models reached 3e-9 here).
    EXPECT_NEAR(r.s.jacobian(1, v), df1[v], 1e-11 * std::abs(f1 / (v == 1 ? e : w)));
    EXPECT_NEAR(r.s.jacobian(2, v), df2[v], 1e-11 * std::abs(f2 / (v == 1 ? e : w)));
  }
  EXPECT_TRUE(r.s.warnings.empty());
}

// A square section: the two bending frequencies are equal. As the width grows, bending in y
// (E h w^3 / 12) stiffens three times as fast as bending in z (E w h^3 / 12): the derivatives of
// the pair are the cluster's, 1 : 3, and a warning says the response sits on a crossing.
TEST(Sensitivities, RepeatedFrequencyGetsTheDirectionalDerivativesOfItsCluster) {
  std::string text = kCantilever;
  text.replace(text.find("\"width\": 0.012"), 14, "\"width\": 0.010");
  Diagnostics diag;
  const auto study = load(text, diag);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator evaluator(*study);
  const Result r = at(evaluator, values(*study));
  const double f = r.outcome.responses[1], w = 0.01;
  EXPECT_NEAR(r.outcome.responses[2] / f, 1.0, 1e-12);
  std::printf("square section: d f1/dw %.10e, d f2/dw %.10e; closed forms %.10e, %.10e\n",
              r.s.jacobian(1, 0), r.s.jacobian(2, 0), f / (2 * w), 3 * f / (2 * w));
  EXPECT_NEAR(r.s.jacobian(1, 0) / (f / (2 * w)), 1.0, 1e-11);
  EXPECT_NEAR(r.s.jacobian(2, 0) / (3 * f / (2 * w)), 1.0, 1e-11);
  // Forward differences agree: each frequency moves at its own rate as w grows.
  const double step = 1e-7;
  const DesignOutcome up = evaluator.evaluate({w + step, 2.1e11, 3.0});
  EXPECT_NEAR((up.responses[1] - f) / step / r.s.jacobian(1, 0), 1.0, 1e-4);
  EXPECT_NEAR((up.responses[2] - f) / step / r.s.jacobian(2, 0), 1.0, 1e-4);
  ASSERT_FALSE(r.s.warnings.empty());
  EXPECT_NE(r.s.warnings[0].find("on a crossing of modes"), std::string::npos) << r.s.warnings[0];
}

// A clamped-free column of 8 segments under an axial load: K0 is proportional to E and K1 does
// not depend on it (the column is statically determinate), so the factor is proportional to E.
TEST(Sensitivities, BucklingFactorIsProportionalToE) {
  const char* text = R"({"name": "column", "scene": {
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"c": {"shape": "circle", "diameter": 0.02}},
    "bodies": [{"name": "top", "mass": 1, "inertia": [1e-4, 1e-4, 1e-4], "position": [0, 0, 2]}],
    "beams": [{"name": "col", "body1": "ground", "body2": "top", "point1": [0, 0, 0],
               "point2": [0, 0, 2], "point3": [1, 0, 0], "material": "steel", "section": "c",
               "segments": 8}],
    "loads": [{"type": "force", "body": "top", "value": [0, 0, -1000]}]},
  "analyses": [{"type": "buckling"}],
  "responses": {"lambda": {"quantity": "buckling_factor", "mode": 1}},
  "study": {"type": "sensitivity", "variables": [
    {"name": "E", "pointer": "/scene/materials/steel/E"},
    {"name": "P", "pointer": "/scene/loads/0/value/2", "factors": [-1]}]}})";
  Diagnostics diag;
  const auto study = load(text, diag);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator evaluator(*study);
  const Result r = at(evaluator, values(*study));
  const double lambda = r.outcome.responses[0];
  std::printf(
      "column: lambda %.10f, d lambda/dE %.10e (lambda/E %.10e), d lambda/dP %.10e "
      "(-lambda/P %.10e)\n",
      lambda, r.s.jacobian(0, 0), lambda / 2.1e11, r.s.jacobian(0, 1), -lambda / 1000);
  // Exact (third-order jets for K1's derivative), to rounding: the differences of the models used
  // before reached 2.6e-10.
  EXPECT_NEAR(r.s.jacobian(0, 0) / (lambda / 2.1e11), 1.0, 1e-12);
  // The factor scales the load: lambda P is the buckling load, whatever P.
  EXPECT_NEAR(r.s.jacobian(0, 1) / (-lambda / 1000), 1.0, 1e-12);
}

// The frame of tests/optimizer/sensitivities_test: see the file comment.
const char* kFrame = R"json({
  "name": "frame_sens",
  "scene": {
    "gravity": [0, 0, -9.81],
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"col": {"shape": "tube", "outer_diameter": 0.06, "wall": 0.004},
                 "gird": {"shape": "box", "width": 0.06, "height": 0.08, "wall": 0.004}},
    "bodies": [
      {"name": "knee_left", "mass": 3, "inertia": [0.01, 0.01, 0.01], "position": [0, 0, 3]},
      {"name": "knee_right", "mass": 3, "inertia": [0.01, 0.01, 0.01], "position": [4, 0, 3]},
      {"name": "payload", "mass": 40, "inertia": [0.5, 0.6, 0.7], "position": [2, 0.1, 3.3]}],
    "beams": [
      {"name": "column_left", "body1": "ground", "body2": "knee_left", "point1": [0, 0, 0],
       "point2": [0, 0, 3], "point3": [1, 0, 0], "material": "steel", "section": "col",
       "segments": 4},
      {"name": "column_right", "body1": "ground", "body2": "knee_right", "point1": [4, 0, 0],
       "point2": [4, 0, 3], "point3": [5, 0, 0], "material": "steel", "section": "col",
       "segments": 4},
      {"name": "girder", "body1": "knee_left", "body2": "knee_right", "point1": [0, 0, 3],
       "point2": [4, 0, 3], "point3": [0, 0, 4], "material": "steel", "section": "gird",
       "segments": 4},
      {"name": "strut_l", "body1": "knee_left", "body2": "payload", "point1": [0.2, 0, 3],
       "point2": [2, 0.1, 3.3], "point3": [0.2, 0, 4], "material": "steel", "section": "col"},
      {"name": "strut_r", "body1": "knee_right", "body2": "payload", "point1": [3.8, 0, 3],
       "point2": [2, 0.1, 3.3], "point3": [3.8, 0, 4], "material": "steel", "section": "col"}],
    "loads": [
      {"type": "force", "body": "knee_left", "value": [1000, 200, 0], "case": "wind"},
      {"type": "force", "body": "payload", "point": [2, 0.1, 3.4], "value": [0, 0, -5000],
       "case": "axial"}]},
  "analyses": [
    {"type": "static", "load_case": "wind", "name": "wind", "tolerance": 1e-14},
    {"type": "modal", "modes": 4, "about": "static", "load_case": "wind"},
    {"type": "buckling", "load_case": "axial", "modes": 2}],
  "responses": {
    "sway": {"quantity": "displacement", "body": "knee_left", "direction": [1, 0, 0],
             "analysis": "wind"},
    "twist": {"quantity": "rotation", "body": "payload", "axis": [0, 0, 1], "analysis": "wind"},
    "n_strut": {"quantity": "element_force", "element": "strut_l", "end": 2, "component": "fx",
                "analysis": "wind"},
    "stress": {"quantity": "max_stress", "analysis": "wind"},
    "f1": {"quantity": "frequency", "mode": 1},
    "f3": {"quantity": "frequency", "mode": 3},
    "buck": {"quantity": "buckling_factor", "mode": 1},
    "mass": {"quantity": "mass"},
    "m_payload": {"quantity": "mass", "bodies": ["payload"], "elements": ["strut_l"]},
    "worst": {"quantity": "expression", "expression": "sqrt(sway^2 + 0.01*twist^2)"}},
  "study": {"type": "sensitivity", "variables": [
    {"name": "d_col", "pointer": "/scene/sections/col/outer_diameter"},
    {"name": "wall_gird", "pointer": "/scene/sections/gird/wall"},
    {"name": "E", "pointer": "/scene/materials/steel/E"},
    {"name": "rho", "pointer": "/scene/materials/steel/density"},
    {"name": "strut_x", "pointer": ["/scene/beams/3/point1/0", "/scene/beams/3/point3/0"]},
    {"name": "m_pay", "pointer": "/scene/bodies/2/mass"},
    {"name": "J_pay", "pointer": "/scene/bodies/2/inertia/2"},
    {"name": "pay_y", "pointer": ["/scene/bodies/2/position/1", "/scene/beams/3/point2/1",
                                  "/scene/beams/4/point2/1"]},
    {"name": "wind", "pointer": "/scene/loads/0/value/0"},
    {"name": "load_z", "pointer": "/scene/loads/1/value/2"}]}})json";

TEST(Sensitivities, EveryResponseKindAgainstEveryVariableKindMatchesExtrapolatedDifferences) {
  Diagnostics diag;
  const auto study = load(kFrame, diag);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator evaluator(*study);
  const std::vector<double> x = values(*study);
  const Result r = at(evaluator, x);
  ASSERT_TRUE(r.s.ok) << r.s.message;
  const size_t nr = study->responses.size();
  double worst = 0.0, worst_small = 0.0;
  int compared = 0;
  for (size_t j = 0; j < x.size(); ++j) {
    // Central differences at steps 1e-3 and 5e-4 (relative), extrapolated: error ~1e-12
    // relative plus the analyses' rounding over the step.
    const std::vector<double> differences =
        testing::extrapolated_differences(evaluator, x, j, 1e-3 * std::abs(x[j]), nr);
    for (size_t k = 0; k < nr; ++k) {
      const double reference = differences[k];
      const double exact = r.s.jacobian(k, j);
      // The responses carry rounding errors of ~1e-11 of their value (an element force from a
      // strain of 1e-5 measured on positions of 1 m), so a derivative is resolved to about that
      // over the step, relative to |r / x|: relative agreement where the response changes by at
      // least a tenth of the variable's relative change, absolute (1e-6 |r / x|) below.
      const double scale = std::abs(r.outcome.responses[k] / x[j]);
      const double relative = std::abs(exact - reference) / std::abs(reference);
      if (std::abs(reference) >= 0.1 * scale) {
        worst = std::max(worst, relative);
        ++compared;
        EXPECT_LT(relative, 1e-6) << study->responses[k].name << " / "
                                  << study->design->variables[j].name << ": " << exact << " vs "
                                  << reference;
      } else {
        worst_small = std::max(worst_small, std::abs(exact - reference) / scale);
        EXPECT_LT(std::abs(exact - reference), 1e-6 * scale)
            << study->responses[k].name << " / " << study->design->variables[j].name << ": "
            << exact << " vs " << reference;
      }
    }
  }
  std::printf(
      "frame: %d well-conditioned derivatives, largest relative difference %.2e; the others "
      "within %.2e of |r / x|\n",
      compared, worst, worst_small);
}

TEST(Sensitivities, ResponsesWithoutExactDerivativesSaySo) {
  std::string text = kCantilever;
  text.replace(text.find("{\"type\": \"static\"}"), 18,
               R"({"type": "transient", "t_end": 0.01, "output_step": 0.001})");
  text.replace(text.find("\"dy\": {\"quantity\": \"displacement\""), 33,
               R"("dy": {"quantity": "peak_displacement")");
  Diagnostics diag;
  const auto study = load(text, diag);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator evaluator(*study);
  ResponseSensitivities s;
  const DesignOutcome o = evaluator.evaluate(values(*study), &s);
  ASSERT_EQ(o.status, Status::kOk) << o.message;
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("\"dy\" (the peak of a transient) has no exact derivative"),
            std::string::npos)
      << s.message;
}

// A follower tip force (turned 0.24 rad with the tip): the equilibrium's derivatives are exact
// (the full tangent, its non-symmetric load stiffness included), against extrapolated central
// differences of whole evaluations; the frequencies about that equilibrium (a non-symmetric
// eigenproblem) have none, and say so.
// A load's time function is part of the scene: the tip load ramps from 0 at t = 0 to 3 N at
// t = to = 2 s, the static analysis reads it at t = 1 s (factor t / to): d dy/d to = -dy / to.
TEST(Sensitivities, ATimeFunctionsParametersAreDesignNumbers) {
  Diagnostics diag;
  auto document = parse_json(kCantilever, "sensitivities.json", diag);
  ASSERT_TRUE(document) << diag.format();
  (*document)["scene"]["loads"][0]["time"] = Json{{"type", "ramp"}, {"from", 0}, {"to", 2.0}};
  (*document)["analyses"][0]["time"] = 1.0;
  (*document)["study"]["variables"] = Json::parse(
      R"([{"name": "to", "pointer": "/scene/loads/0/time/to"},
          {"name": "F", "pointer": "/scene/loads/0/value/1", "factors": [-1]}])");
  const auto study = load_study(*document, "sensitivities.json", ".", diag);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator evaluator(*study);
  const Result r = at(evaluator, {2.0, 3.0});
  const double dy = r.outcome.responses[0];
  std::printf("ramp: dy %.10e, d dy/d to %.10e (-dy/to %.10e), d dy/dF %.10e (dy/F %.10e)\n", dy,
              r.s.jacobian(0, 0), -dy / 2.0, r.s.jacobian(0, 1), dy / 3.0);
  // dy is F(t) L^3 / (3 E I) to ~1e-6 (the nonlinearity); its derivatives with respect to the
  // ramp's end and to the load are the same function of F(t) = F t / to, so their ratio is exact.
  EXPECT_NEAR(r.s.jacobian(0, 0) / r.s.jacobian(0, 1), -3.0 / 2.0, 1e-12);
  EXPECT_NEAR(r.s.jacobian(0, 0) / (-dy / 2.0), 1.0, 1e-5);
}

// A thin strip (width / height 250: the torsion series' exp(2 x) overflows a double) keeps finite
// derivatives; and a static analysis read at the ramp's end says its derivative with respect to
// that end is one-sided.
TEST(Sensitivities, AThinStripAndARampsEndKeepFiniteOrFlaggedDerivatives) {
  Diagnostics diag;
  auto document = parse_json(kCantilever, "sensitivities.json", diag);
  ASSERT_TRUE(document) << diag.format();
  (*document)["scene"]["sections"]["r"] =
      Json{{"shape", "rectangle"}, {"width", 0.05}, {"height", 0.0002}};
  (*document)["scene"]["loads"][0]["time"] = Json{{"type", "ramp"}, {"from", 0}, {"to", 2.0}};
  (*document)["scene"]["loads"][0]["value"][1] = -1e-6;
  (*document)["analyses"][0]["time"] = 2.0;
  (*document)["study"]["variables"] = Json::parse(
      R"([{"name": "to", "pointer": "/scene/loads/0/time/to"},
          {"name": "h", "pointer": "/scene/sections/r/height"}])");
  const auto study = load_study(*document, "sensitivities.json", ".", diag);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator evaluator(*study);
  const Result r = at(evaluator, {2.0, 0.0002});
  ASSERT_TRUE(r.s.ok) << r.s.message;
  EXPECT_TRUE(r.s.jacobian.allFinite()) << r.s.jacobian;
  // The frequencies grow with the strip's height (bending about its thin axis: EI ~ h^3).
  EXPECT_GT(r.s.jacobian(1, 1), 0.0);
  bool flagged = false;
  for (const std::string& w : r.s.warnings)
    flagged =
        flagged || w.find("moves a breakpoint of a load's time function") != std::string::npos;
  EXPECT_TRUE(flagged);
}

// The derivatives follow the scene's numbers through its build: a variable on an analysis's option
// or on a number the build does not differentiate (a segment count) has none, and says so rather
// than giving 0.
TEST(Sensitivities, VariablesTheSceneBuildDoesNotDifferentiateSaySo) {
  const std::pair<std::string, std::string> cases[] = {
      {"/analyses/1/modes", "/analyses/1/modes is not a number of the inline scene"},
      {"/scene/beams/0/segments",
       "/scene/beams/0/segments: not a number the scene's build differentiates"}};
  for (const auto& [pointer, message] : cases) {
    Diagnostics diag;
    auto document = parse_json(kCantilever, "sensitivities.json", diag);
    ASSERT_TRUE(document) << diag.format();
    // A segmented arm (which needs a density) for the count to address.
    (*document)["scene"]["beams"][0]["segments"] = 2;
    (*document)["scene"]["materials"]["steel"]["density"] = 7850;
    Json& variables = (*document)["study"]["variables"];
    variables.insert(variables.begin(), Json{{"name", "v"}, {"pointer", pointer}});
    const auto study = load_study(*document, "sensitivities.json", ".", diag);
    ASSERT_TRUE(study) << diag.format();
    const DesignEvaluator evaluator(*study);
    ResponseSensitivities s;
    const DesignOutcome o = evaluator.evaluate(values(*study), &s);
    ASSERT_EQ(o.status, Status::kOk) << o.message;
    EXPECT_FALSE(s.ok);
    EXPECT_NE(s.message.find(message), std::string::npos) << s.message;
    EXPECT_NE(s.message.find("an optimization can take \"gradient\": \"fd\""), std::string::npos)
        << s.message;
  }
}

TEST(Sensitivities, FollowerLoadEquilibriumIsExactItsFrequenciesAreRefused) {
  std::string text = kCantilever;
  const std::string dead = R"("value": [0, -3, 0]})";
  text.replace(text.find(dead), dead.size(), R"("value": [0, -100, 0], "follows": true})");
  const std::string dy =
      R"("dy": {"quantity": "displacement", "body": "tip", "direction": [0, -1, 0]},)";
  text.replace(
      text.find(dy), dy.size(),
      dy + R"("dx": {"quantity": "displacement", "body": "tip", "direction": [1, 0, 0]},)");
  const std::string frequencies = R"(,
    "f1": {"quantity": "frequency", "mode": 1},
    "f2": {"quantity": "frequency", "mode": 2}})";
  const size_t at_frequencies = text.find(frequencies);
  const std::string statics =
      text.substr(0, at_frequencies) + "}" + text.substr(at_frequencies + frequencies.size());
  Diagnostics diag;
  const auto study = load(statics, diag);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator evaluator(*study);
  const std::vector<double> x = values(*study);
  const Result r = at(evaluator, x);
  ASSERT_TRUE(r.s.ok) << r.s.message;
  for (size_t j = 0; j < x.size(); ++j) {
    const auto central = [&](double h) {
      std::vector<double> up = x, down = x;
      up[j] += h, down[j] -= h;
      const DesignOutcome u = evaluator.evaluate(up), d = evaluator.evaluate(down);
      return Eigen::Vector2d((u.responses[0] - d.responses[0]) / (2 * h),
                             (u.responses[1] - d.responses[1]) / (2 * h));
    };
    const double h = 1e-3 * std::abs(x[j]);
    const Eigen::Vector2d reference = (4 * central(h / 2) - central(h)) / 3;
    for (int k = 0; k < 2; ++k) {
      std::printf("follower load: d %s / d %s = %.10e (differences %.10e)\n",
                  study->responses[k].name.c_str(), study->design->variables[j].name.c_str(),
                  r.s.jacobian(k, j), reference(k));
      EXPECT_NEAR(r.s.jacobian(k, j), reference(k), 1e-6 * std::abs(reference(k)));
    }
  }

  text.replace(text.find(R"("about": "initial")"), 18, R"("about": "static")");
  const auto modal = load(text, diag);
  ASSERT_TRUE(modal) << diag.format();
  const DesignEvaluator modal_evaluator(*modal);
  ResponseSensitivities s;
  const DesignOutcome o = modal_evaluator.evaluate(values(*modal), &s);
  ASSERT_EQ(o.status, Status::kOk) << o.message;
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("\"f1\" is a frequency of a non-symmetric eigenproblem (torques of "
                           "fixed direction or follower loads)"),
            std::string::npos)
      << s.message;
}

}  // namespace
}  // namespace beamrail
