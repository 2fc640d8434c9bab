// Design sensitivities where a response is not smooth in the variables, found by an adversarial
// review (2026-12-01) to come out wrong without a warning:
//  - a mode repeated with the next one, which the analysis was not asked for (a square section's
//    bending pair with one mode asked): the derivative took an arbitrary mix of the pair's shapes;
//    the analyses now compute two more modes for the derivatives (kSensitivityGuardModes), and
//    the derivative is the one as the variable grows (closed forms: a pair's lower branch grows
//    as lambda / w, proportional to the second moment that grows linearly in w);
//  - max_stress where a moment is zero: |Mz| at -1e-16 gave the sign of rounding noise; it now
//    grows as |dMz| either way (one-sided differences on both sides);
//  - joint_gap of a joint carrying nothing: 0 where |g| grows as |dg| (its closed form m / k_f);
//  - an expression max(dy, c) at dy = c: half the slope (muparser's central difference averages
//    the two sides, and so did the study's own central-difference check); now the slope as the
//    variable grows, from one-sided differences along it.
// Each warns that the derivative is the one as the variables grow.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/scene/json_reader.hpp"
#include "optimizer/run/designs.hpp"

namespace beamrail {
namespace {

std::optional<Study> load(const std::string& text, Diagnostics& diag) {
  const auto document = parse_json(text, "kinks.json", diag);
  if (!document) return std::nullopt;
  return load_study(*document, "kinks.json", ".", diag);
}

bool warns(const ResponseSensitivities& s, const std::string& words) {
  for (const std::string& w : s.warnings)
    if (w.find(words) != std::string::npos) return true;
  return false;
}

// A 2 kg tip (rotary inertia 1e-6) on a massless 1 m steel cantilever of a square 10 mm section:
// its two bending frequencies are equal; one mode asked for.
const char* kSquareTip = R"({"name": "tip", "scene": {
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"r": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [{"name": "tip", "mass": 2.0, "inertia": [1e-6, 1e-6, 1e-6], "position": [1, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "r"}]},
  "analyses": [{"type": "modal", "modes": 1, "about": "initial"}],
  "responses": {"f1": {"quantity": "frequency", "mode": 1}},
  "study": {"type": "sensitivity", "variables": [
    {"name": "w", "pointer": "/scene/sections/r/width"}]}})";

// Before: d f1/dw came out of an arbitrary mix of the pair (between f/(2w) and 3f/(2w)).
TEST(SensitivityKinks, AModeRepeatedWithOneNotAskedForGrowsAlongItsLowerBranch) {
  Diagnostics diag;
  const auto study = load(kSquareTip, diag);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator evaluator(*study);
  const double w = 0.01;
  ResponseSensitivities s;
  const DesignOutcome at = evaluator.evaluate({w}, &s);
  ASSERT_EQ(at.status, Status::kOk) << at.message;
  ASSERT_TRUE(s.ok) << s.message;
  const double f = at.responses[0];
  // As w grows the pair splits: bending with the second moment h w^3 / 12 rises 3 times as fast
  // as with w h^3 / 12, so the lowest frequency, f1, goes as sqrt(w): f / (2 w).
  const double step = 1e-7;
  const double up = (evaluator.evaluate({w + step}).responses[0] - f) / step;
  const double down = (f - evaluator.evaluate({w - step}).responses[0]) / step;
  std::printf(
      "square tip, one mode: d f1/dw %.10e; closed form f/(2w) %.10e; forward %.10e, "
      "backward %.10e (3 f/(2w) %.10e)\n",
      s.jacobian(0, 0), f / (2 * w), up, down, 3 * f / (2 * w));
  EXPECT_NEAR(s.jacobian(0, 0) / (f / (2 * w)), 1.0, 1e-10);
  EXPECT_NEAR(up / s.jacobian(0, 0), 1.0, 1e-4);
  EXPECT_NEAR(down / (3 * f / (2 * w)), 1.0, 1e-4);  // the other branch: a kink
  EXPECT_TRUE(warns(s, "on a crossing of modes")) << (s.warnings.empty() ? "" : s.warnings[0]);
}

// The same for a buckling factor: a clamped-free column of a square 20 mm section in 8 segments
// under an axial load, its one default factor of a repeated pair. The factor is proportional to
// the second moment (K1 does not depend on the section: the column is statically determinate),
// and as the width grows the lower branch's grows linearly in it: d lambda/dw = lambda / w.
TEST(SensitivityKinks, ABucklingFactorRepeatedWithOneNotAskedForGrowsAlongItsLowerBranch) {
  const char* text = R"({"name": "column", "scene": {
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"s": {"shape": "rectangle", "width": 0.02, "height": 0.02}},
    "bodies": [{"name": "top", "mass": 1, "inertia": [1e-4, 1e-4, 1e-4], "position": [0, 0, 2]}],
    "beams": [{"name": "col", "body1": "ground", "body2": "top", "point1": [0, 0, 0],
               "point2": [0, 0, 2], "point3": [1, 0, 0], "material": "steel", "section": "s",
               "segments": 8}],
    "loads": [{"type": "force", "body": "top", "value": [0, 0, -1000]}]},
  "analyses": [{"type": "buckling"}],
  "responses": {"lambda": {"quantity": "buckling_factor", "mode": 1}},
  "study": {"type": "sensitivity", "variables": [
    {"name": "w", "pointer": "/scene/sections/s/width"}]}})";
  Diagnostics diag;
  const auto study = load(text, diag);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator evaluator(*study);
  const double w = 0.02;
  ResponseSensitivities s;
  const DesignOutcome at = evaluator.evaluate({w}, &s);
  ASSERT_EQ(at.status, Status::kOk) << at.message;
  ASSERT_TRUE(s.ok) << s.message;
  const double lambda = at.responses[0];
  const double step = 1e-8;
  const double up = (evaluator.evaluate({w + step}).responses[0] - lambda) / step;
  const double down = (lambda - evaluator.evaluate({w - step}).responses[0]) / step;
  std::printf(
      "square column, one factor: d lambda/dw %.10e; closed form lambda/w %.10e; "
      "forward %.10e, backward %.10e (3 lambda/w %.10e)\n",
      s.jacobian(0, 0), lambda / w, up, down, 3 * lambda / w);
  EXPECT_NEAR(s.jacobian(0, 0) / (lambda / w), 1.0, 1e-9);
  EXPECT_NEAR(up / s.jacobian(0, 0), 1.0, 1e-4);
  EXPECT_NEAR(down / (3 * lambda / w), 1.0, 1e-4);
  EXPECT_TRUE(warns(s, "repeated factor")) << (s.warnings.empty() ? "" : s.warnings[0]);
}

// A cantilever of a 12 x 10 mm section along x loaded along -y at its tip (3 N): its moment about
// the section's other axis is zero. The variable p turns the section's axes about the beam
// (point3 = (0, 1, p)): the stress |My|/Wy + |Mz|/Wz is V-shaped about p = 0, growing either way.
TEST(SensitivityKinks, AStressWhoseMomentIsZeroGrowsEitherWay) {
  const char* text = R"({"name": "turned", "scene": {
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"r": {"shape": "rectangle", "width": 0.012, "height": 0.01}},
    "bodies": [{"name": "tip", "mass": 2.0, "inertia": [1e-6, 1e-6, 1e-6], "position": [1, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "r"}],
    "loads": [{"type": "force", "body": "tip", "value": [0, -3, 0]}]},
  "analyses": [{"type": "static"}],
  "responses": {"stress": {"quantity": "max_stress"}},
  "study": {"type": "sensitivity", "variables": [
    {"name": "p", "pointer": "/scene/beams/0/point3/2"}]}})";
  Diagnostics diag;
  const auto study = load(text, diag);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator evaluator(*study);
  ResponseSensitivities s;
  const DesignOutcome at = evaluator.evaluate({0.0}, &s);
  ASSERT_EQ(at.status, Status::kOk) << at.message;
  ASSERT_TRUE(s.ok) << s.message;
  const double stress = at.responses[0], step = 1e-6;
  const double up = (evaluator.evaluate({step}).responses[0] - stress) / step;
  const double down = (stress - evaluator.evaluate({-step}).responses[0]) / step;
  std::printf(
      "turned section: stress %.10e Pa, d stress/dp %.10e; forward %.10e, backward "
      "%.10e\n",
      stress, s.jacobian(0, 0), up, down);
  ASSERT_GT(up, 0.0);
  EXPECT_NEAR(down / up, -1.0, 1e-3);  // V-shaped
  EXPECT_NEAR(s.jacobian(0, 0) / up, 1.0, 1e-3);
  EXPECT_TRUE(warns(s, "is at a kink")) << (s.warnings.empty() ? "" : s.warnings[0]);

  // Away from the kink the derivative is the smooth one, without a warning.
  ResponseSensitivities off;
  const double p = 0.05;
  const DesignOutcome turned = evaluator.evaluate({p}, &off);
  ASSERT_EQ(turned.status, Status::kOk) << turned.message;
  const double central =
      (evaluator.evaluate({p + step}).responses[0] - evaluator.evaluate({p - step}).responses[0]) /
      (2 * step);
  std::printf("at p = 0.05: d stress/dp %.10e, central differences %.10e\n", off.jacobian(0, 0),
              central);
  EXPECT_NEAR(off.jacobian(0, 0) / central, 1.0, 1e-5);
  EXPECT_FALSE(warns(off, "is at a kink"));
}

// A 2 kg weight welded (a fixed joint of relative compliance 0.1) to the 1 kg tip of a 12 x 10 mm
// steel cantilever, gravity g along -y as the variable, at g = 0: the weld carries nothing. Its
// gap grows with |g| either way (linearly, to the deflection's second order): d|gap|/dg is
// gap(g) / g as g grows, where 0 was given.
TEST(SensitivityKinks, TheGapOfAJointCarryingNothingGrowsEitherWay) {
  const char* text = R"({"name": "weld", "scene": {
    "gravity": [0, 0, 0],
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"r": {"shape": "rectangle", "width": 0.012, "height": 0.01}},
    "bodies": [{"name": "tip", "mass": 1.0, "inertia": [1e-4, 1e-4, 1e-4], "position": [1, 0, 0]},
               {"name": "weight", "mass": 2.0, "inertia": [2e-3, 3e-3, 4e-3],
                "position": [1.1, 0.02, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "r"}],
    "joints": [{"name": "weld", "type": "fixed", "body1": "tip", "body2": "weight",
                "point": [1.05, 0, 0], "relative_compliance": 0.1}]},
  "analyses": [{"type": "static", "tolerance": 1e-14}],
  "responses": {"gap": {"quantity": "joint_gap", "joint": "weld"}},
  "study": {"type": "sensitivity", "variables": [
    {"name": "g", "pointer": "/scene/gravity/1", "factors": [-1]}]}})";
  Diagnostics diag;
  const auto study = load(text, diag);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator evaluator(*study);
  ResponseSensitivities s;
  const DesignOutcome at = evaluator.evaluate({0.0}, &s);
  ASSERT_EQ(at.status, Status::kOk) << at.message;
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(at.responses[0], 0.0);
  const double g = 1e-3;
  const double up = evaluator.evaluate({g}).responses[0] / g;
  const double down = -evaluator.evaluate({-g}).responses[0] / g;
  std::printf("joint carrying nothing: d gap/dg %.6e; gap(g)/g %.6e, -gap(-g)/g %.6e\n",
              s.jacobian(0, 0), up, down);
  ASSERT_GT(up, 0.0);
  EXPECT_NEAR(down / up, -1.0, 1e-3);
  EXPECT_NEAR(s.jacobian(0, 0) / up, 1.0, 1e-3);
  EXPECT_TRUE(warns(s, "is at a kink")) << (s.warnings.empty() ? "" : s.warnings[0]);
}

// A 1 m cantilever of a 12 x 10 mm steel section with a 2 kg tip under a tip load F (3 N): dy =
// F L^3 / (3 E I), linear in F. Expressions of dy with a kink at this design: max(dy, c) and
// min(dy, c) with c = dy. As F grows max follows dy (d/dF = dy / F) and min stays c (0); the
// central differences gave half of dy / F for both. A smooth expression keeps its chain rule.
TEST(SensitivityKinks, AnExpressionAtAKinkTakesTheSlopeAsTheVariableGrows) {
  const std::string scene = R"("scene": {
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"r": {"shape": "rectangle", "width": 0.012, "height": 0.01}},
    "bodies": [{"name": "tip", "mass": 2.0, "inertia": [1e-6, 1e-6, 1e-6], "position": [1, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "r"}],
    "loads": [{"type": "force", "body": "tip", "value": [0, -3, 0]}]},
  "analyses": [{"type": "static"}],)";
  const std::string variables = R"("study": {"type": "sensitivity", "variables": [
    {"name": "F", "pointer": "/scene/loads/0/value/1", "factors": [-1]}]}})";
  Diagnostics diag;
  const auto plain = load(R"({"name": "dy", )" + scene + R"(
    "responses": {"dy": {"quantity": "displacement", "body": "tip", "direction": [0, -1, 0]}},
    )" + variables,
                          diag);
  ASSERT_TRUE(plain) << diag.format();
  const double dy = DesignEvaluator(*plain).evaluate({3.0}).responses[0], f = 3.0;
  char c[32];
  std::snprintf(c, sizeof c, "%.17g", dy);
  const std::string tie = c;
  const auto study = load(R"({"name": "kinks", )" + scene + R"x(
    "responses": {"dy": {"quantity": "displacement", "body": "tip", "direction": [0, -1, 0]},
                  "upper": {"quantity": "expression", "expression": "max(dy, )x" +
                              tie + R"x()"},
                  "lower": {"quantity": "expression", "expression": "min(dy, )x" +
                              tie + R"x()"},
                  "square": {"quantity": "expression", "expression": "dy^2"}},
    )x" + variables,
                          diag);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator evaluator(*study);
  ResponseSensitivities s;
  const DesignOutcome at = evaluator.evaluate({f}, &s);
  ASSERT_EQ(at.status, Status::kOk) << at.message;
  ASSERT_TRUE(s.ok) << s.message;
  // The responses by name (the study orders them by name: dy, lower, square, upper).
  const auto index = [&](const std::string& name) {
    for (size_t k = 0; k < study->responses.size(); ++k)
      if (study->responses[k].name == name) return static_cast<int>(k);
    ADD_FAILURE() << "no response " << name;
    return 0;
  };
  const int y = index("dy"), upper = index("upper"), lower = index("lower"),
            square = index("square");
  ASSERT_EQ(at.responses[upper], dy);
  ASSERT_EQ(at.responses[lower], dy);
  std::printf(
      "dy %.10e: d dy/dF %.10e (dy/F %.10e); d max/dF %.10e, d min/dF %.10e, "
      "d dy^2/dF %.10e (2 dy^2/F %.10e)\n",
      dy, s.jacobian(y, 0), dy / f, s.jacobian(upper, 0), s.jacobian(lower, 0),
      s.jacobian(square, 0), 2 * dy * dy / f);
  EXPECT_NEAR(s.jacobian(y, 0) / (dy / f), 1.0, 1e-5);  // the geometric nonlinearity: ~(dy/L)^2
  EXPECT_NEAR(s.jacobian(upper, 0) / s.jacobian(y, 0), 1.0, 1e-6);
  EXPECT_NEAR(s.jacobian(lower, 0), 0.0, 1e-6 * s.jacobian(y, 0));
  EXPECT_NEAR(s.jacobian(square, 0) / (2 * dy * s.jacobian(y, 0)), 1.0, 1e-8);
  int kinks = 0;
  for (const std::string& w : s.warnings) kinks += w.find("has a kink") != std::string::npos;
  EXPECT_EQ(kinks, 2);
  EXPECT_FALSE(warns(s, "\"square\" has a kink"));
  // One-sided differences of whole evaluations agree.
  const double step = 1e-6;
  const DesignOutcome up = evaluator.evaluate({f + step});
  EXPECT_NEAR((up.responses[upper] - dy) / step / s.jacobian(upper, 0), 1.0, 1e-5);
  EXPECT_NEAR((up.responses[lower] - dy) / step, 0.0, 1e-9 * s.jacobian(y, 0));
}

}  // namespace
}  // namespace beamrail
