// Design sensitivities of a scene with joints (optimizer/run/sensitivities.hpp): a cantilever whose
// tip carries a weight welded by a fixed joint, the weight also propped by a strut through a
// spherical joint, loaded and under gravity; a static analysis and a modal one about its
// equilibrium. Every response (a displacement,
// the joints' end forces and gap, two frequencies) against every variable (the section, E, the
// weight's mass, where the weld sits, its relative compliance, a load) agrees with extrapolated
// central differences of whole evaluations, as tests/optimizer/sensitivities_test.cpp checks a
// frame without joints.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "core/scene/json_reader.hpp"
#include "optimizer/run/designs.hpp"
#include "tests/support/design_differences.hpp"

namespace beamrail {
namespace {

const char* kJointed = R"json({"name": "jointed", "scene": {
    "gravity": [0, -9.81, 0],
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"r": {"shape": "rectangle", "width": 0.012, "height": 0.01}},
    "bodies": [{"name": "tip", "mass": 1.0, "inertia": [1e-4, 1e-4, 1e-4], "position": [1, 0, 0]},
               {"name": "weight", "mass": 2.0, "inertia": [2e-3, 3e-3, 4e-3], "position": [1.1, 0.02, 0]},
               {"name": "knee", "mass": 0.5, "inertia": [1e-3, 1e-3, 1e-3], "position": [1.1, -0.05, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "r",
               "segments": 3},
              {"name": "strut", "body1": "ground", "body2": "knee", "point1": [1.1, -0.6, 0.1],
               "point2": [1.1, -0.05, 0], "point3": [2, -0.6, 0.1], "material": "steel",
               "section": "r"}],
    "joints": [{"name": "weld", "type": "fixed", "body1": "tip", "body2": "weight",
                "point": [1.05, 0, 0], "relative_compliance": 0.1},
               {"name": "ball", "type": "spherical", "body1": "knee", "body2": "weight",
                "point": [1.1, -0.05, 0], "relative_compliance": 0.1}],
    "loads": [{"type": "force", "body": "weight", "value": [0, -3, 1]}]},
  "analyses": [{"type": "static", "tolerance": 1e-14}, {"type": "modal", "modes": 2, "about": "static"}],
  "responses": {
    "dz": {"quantity": "displacement", "body": "weight", "direction": [0, 0, 1]},
    "weld_fy": {"quantity": "element_force", "element": "weld", "end": 2, "component": "fy"},
    "weld_mx": {"quantity": "element_force", "element": "weld", "end": 2, "component": "mx"},
    "ball_fy": {"quantity": "element_force", "element": "ball", "end": 1, "component": "fy"},
    "weld_gap": {"quantity": "joint_gap", "joint": "weld"},
    "ball_gap": {"quantity": "joint_gap", "joint": "ball"},
    "f1": {"quantity": "frequency", "mode": 1},
    "f2": {"quantity": "frequency", "mode": 2}},
  "study": {"type": "sensitivity", "variables": [
    {"name": "w", "pointer": "/scene/sections/r/width"},
    {"name": "E", "pointer": "/scene/materials/steel/E"},
    {"name": "m_weight", "pointer": "/scene/bodies/1/mass"},
    {"name": "weld_x", "pointer": "/scene/joints/0/point/0"},
    {"name": "weld_c", "pointer": "/scene/joints/0/relative_compliance"},
    {"name": "load_z", "pointer": "/scene/loads/0/value/2"}]}})json";

TEST(JointSensitivities, EveryResponseAgainstEveryVariableMatchesExtrapolatedDifferences) {
  Diagnostics diag;
  const auto document = parse_json(kJointed, "jointed.json", diag);
  ASSERT_TRUE(document) << diag.format();
  const auto study = load_study(*document, "jointed.json", ".", diag);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator evaluator(*study);
  std::vector<double> x;
  for (const DesignVariable& v : study->design->variables) x.push_back(v.value);
  ResponseSensitivities s;
  const DesignOutcome at = evaluator.evaluate(x, &s);
  ASSERT_EQ(at.status, Status::kOk) << at.message;
  ASSERT_TRUE(s.ok) << s.message;
  const size_t nr = study->responses.size();
  double worst = 0.0, worst_small = 0.0;
  int compared = 0;
  for (size_t j = 0; j < x.size(); ++j) {
    // Central differences at steps 2e-3 and 1e-3 (relative), extrapolated (Richardson). A joint's
    // force is its stiffness times a gap of ~1e-7 m: its rounding grows with the stiffness, which
    // is why the joints here are soft (relative compliance 0.1: ten times the stiffest element's
    // compliance). At c = 1e-4 the differences of the joint forces were noise (d ball_fy / d w:
    // 309 against the exact 221.07, which moved by 1.2e-5 from c = 1e-4 to 0.1 while the
    // differences converged on it); at c = 0.1 they resolve them to 1.3e-6 at these steps (7.8e-8
    // at steps 5 times larger, where the frequencies' truncation error grows to 2.7e-4).
    const std::vector<double> differences =
        testing::extrapolated_differences(evaluator, x, j, 2e-3 * std::abs(x[j]), nr);
    for (size_t k = 0; k < nr; ++k) {
      const double reference = differences[k];
      const double exact = s.jacobian(k, j);
      // As in tests/optimizer/sensitivities_test.cpp: relative agreement where the response
      // changes by at least a tenth of the variable's relative change, absolute (1e-6 |r / x|)
      // below.
      const double scale = std::abs(at.responses[k] / x[j]);
      std::printf("d %-9s / d %-8s: exact %+.10e, differences %+.10e\n",
                  study->responses[k].name.c_str(), study->design->variables[j].name.c_str(), exact,
                  reference);
      if (std::abs(reference) >= 0.1 * scale) {
        const double relative = std::abs(exact - reference) / std::abs(reference);
        worst = std::max(worst, relative);
        ++compared;
        EXPECT_LT(relative, 1e-5) << study->responses[k].name << " / "
                                  << study->design->variables[j].name;
      } else {
        worst_small = std::max(worst_small, std::abs(exact - reference) / scale);
        EXPECT_LT(std::abs(exact - reference), 1e-6 * scale)
            << study->responses[k].name << " / " << study->design->variables[j].name;
      }
    }
  }
  std::printf(
      "jointed cantilever: %d well-conditioned derivatives, largest relative difference %.2e; the "
      "others within %.2e of |r / x|\n",
      compared, worst, worst_small);
  EXPECT_GE(compared, 15);
}

}  // namespace
}  // namespace beamrail
