// A carriage on a prismatic or cylindrical rail: it slides freely along the rail, and a lateral
// load at carriage distance a deflects it by P a^3 / (3 E I) whatever a is (docs/model.md
// "Validation").
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "tests/support/transient_run.hpp"

namespace beamrail {
namespace {

using testing::TransientRun;

// A carriage at distance a on a rail fixed to ground along x, loaded by `load` (a JSON vector).
std::string carriage(const std::string& type, const std::string& formulation, double a,
                     const std::string& load, double damping, const std::string& time) {
  const std::string x = std::to_string(a);
  return R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.1e10}},
    "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [{"name": "carriage", "mass": 2.0, "inertia": [1e-4, 1e-4, 1e-4],
                "position": [)" +
         x + R"(, 0, 0]}],
    "rails": [{"name": "guide", "type": ")" +
         type + R"(", "body1": "ground", "body2": "carriage",
               "point1": [0, 0, 0], "point2": [)" +
         x + R"(, 0, 0], "point3": [0, 1, 0],
               "material": "steel", "section": "sq", "formulation": ")" +
         formulation + R"(", "damping": )" + std::to_string(damping) + R"(}],
    "loads": [{"type": "force", "body": "carriage", "value": )" +
         load + R"(, "time": )" + time + "}]}";
}

TEST(RailMotion, AxialPushSlidesTheCarriageWithNoReaction) {
  for (const std::string type : {"prismatic", "cylindrical"})
    for (const std::string formulation : {"energy", "paper"}) {
      // 3 N along the rail on 2 kg: x(t) = 0.5 + 3 t^2 / 4.
      const Model model = testing::scene_from_json(
          carriage(type, formulation, 0.5, "[3, 0, 0]", 0.0, R"({"type": "constant"})"));
      const TransientRun run = testing::simulate(model, testing::options(1.0, 0.01, 1e-10, 1e-13));
      ASSERT_TRUE(run.result.ok) << run.result.message;
      double worst = 0, lateral = 0;
      for (const auto& s : run.samples) {
        const double t = s.sample.t;
        worst = std::max(worst, std::abs(s.c[1](0) - (0.5 + 0.75 * t * t)));
        lateral = std::max(lateral, s.c[1].tail<2>().norm());
      }
      std::printf("%s/%s: axial push over 1 s: |x - x_exact| <= %.2e m, lateral drift %.2e m\n",
                  type.c_str(), formulation.c_str(), worst, lateral);
      EXPECT_LT(worst, 1e-9);
      EXPECT_LT(lateral, 1e-12);
    }
}

TEST(RailMotion, LateralLoadDeflectsByCantileverFormulaAtAnyDistance) {
  const double e = 2.1e11, i = std::pow(0.01, 4) / 12, p = 5.0;
  for (const std::string type : {"prismatic", "cylindrical"})
    for (double a : {0.2, 0.5, 1.0}) {
      // The paper's rail: no force along the rail, so the carriage stays at a. Damping and a
      // ramped load let it settle on the static deflection.
      const Model model = testing::scene_from_json(carriage(
          type, "paper", a, "[0, -5, 0]", 0.05, R"({"type": "ramp", "from": 0, "to": 0.5})"));
      const TransientRun run = testing::simulate(model, testing::options(6.0, 0.1, 1e-10, 1e-14));
      ASSERT_TRUE(run.result.ok) << run.result.message;
      const double deflection = -run.samples.back().c[1](1);
      const double exact = p * a * a * a / (3 * e * i);
      std::printf(
          "%s, a = %.1f m: deflection %.10e m, P a^3/(3EI) = %.10e m, relative error %.2e\n",
          type.c_str(), a, deflection, exact, deflection / exact - 1);
      EXPECT_NEAR(deflection / exact, 1.0, 1e-6);
      EXPECT_NEAR(run.samples.back().c[1](0), a, 1e-12 * a);  // still at distance a
    }
}

}  // namespace
}  // namespace beamrail
