// Static analysis against the closed forms of docs/model.md "Validation" (linear range, 1e-9
// relative).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "core/analysis/static_analysis.hpp"
#include "core/model/rotation.hpp"
#include "tests/support/reference_cantilever.hpp"
#include "tests/support/scenes.hpp"

namespace beamrail {
namespace {

constexpr double kE = 2.1e11, kG = 8.0769e10;

// A cantilever from ground along x to a tip body, section `section`, with loads `loads`.
std::string cantilever(double length, const std::string& section, const std::string& loads) {
  const std::string l = std::to_string(length);
  return R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"s": )" +
         section + R"(},
    "bodies": [{"name": "tip", "mass": 1.0, "inertia": [1e-3, 1e-3, 1e-3], "position": [)" +
         l +
         R"(, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [)" +
         l + R"(, 0, 0], "point3": [0, 1, 0], "material": "steel",
               "section": "s"}],
    "loads": )" +
         loads + "}";
}

struct Equilibrium {
  StaticResult result;
  Vec3 displacement;
  Vec3 rotation;  // rotation vector of the tip body
};

Equilibrium solve(const std::string& json) {
  const Model model = testing::scene_from_json(json);
  Data data(model);
  StaticOptions options;
  options.tolerance = 1e-13;
  Equilibrium e;
  e.result = solve_static(model, options, data);
  const int tip = model.free_bodies[0];
  e.displacement = data.pose[tip].u;
  e.rotation = rotation_vector(data.pose[tip].A);
  return e;
}

void expect_relative(double measured, double exact, const char* what) {
  std::printf("%-40s measured % .12e  exact % .12e  relative error %.2e\n", what, measured, exact,
              std::abs(measured / exact - 1));
  EXPECT_NEAR(measured / exact, 1.0, 1e-9) << what;
}

const char* kSquare = R"({"shape": "rectangle", "width": 0.01, "height": 0.012})";

TEST(Static, TipLoadsOnACantileverMatchClosedForms) {
  const double l = 0.8, w = 0.01, h = 0.012;
  const double area = w * h, iz = h * w * w * w / 12, iy = w * h * h * h / 12;
  {
    const Equilibrium e = solve(
        cantilever(l, kSquare, R"([{"type": "force", "body": "tip", "value": [250, 0, 0]}])"));
    ASSERT_TRUE(e.result.ok) << e.result.message;
    expect_relative(e.displacement(0), 250 * l / (kE * area), "axial P l / (E S)");
  }
  {
    const double p = 2e-3;
    const Equilibrium e = solve(
        cantilever(l, kSquare, R"([{"type": "force", "body": "tip", "value": [0, -2e-3, 0]}])"));
    ASSERT_TRUE(e.result.ok) << e.result.message;
    expect_relative(-e.displacement(1), p * l * l * l / (3 * kE * iz),
                    "bending in y: P l^3 / (3 E Iz)");
    expect_relative(-e.rotation(2), p * l * l / (2 * kE * iz), "bending in y: P l^2 / (2 E Iz)");
  }
  {
    const double p = 3e-3;
    const Equilibrium e = solve(
        cantilever(l, kSquare, R"([{"type": "force", "body": "tip", "value": [0, 0, 3e-3]}])"));
    ASSERT_TRUE(e.result.ok) << e.result.message;
    expect_relative(e.displacement(2), p * l * l * l / (3 * kE * iy),
                    "bending in z: P l^3 / (3 E Iy)");
    expect_relative(-e.rotation(1), p * l * l / (2 * kE * iy), "bending in z: P l^2 / (2 E Iy)");
  }
  {
    const double m = 1e-3;
    const Equilibrium e = solve(
        cantilever(l, kSquare, R"([{"type": "torque", "body": "tip", "value": [0, 0, 1e-3]}])"));
    ASSERT_TRUE(e.result.ok) << e.result.message;
    expect_relative(e.displacement(1), m * l * l / (2 * kE * iz), "tip moment: M l^2 / (2 E Iz)");
    expect_relative(e.rotation(2), m * l / (kE * iz), "tip moment: M l / (E Iz)");
  }
  {
    const double t = 1e-2;
    const Model model = testing::scene_from_json(cantilever(l, kSquare, "[]"));
    const double ix = model.beams[0].gj / kG;
    const Equilibrium e = solve(
        cantilever(l, kSquare, R"([{"type": "torque", "body": "tip", "value": [1e-2, 0, 0]}])"));
    ASSERT_TRUE(e.result.ok) << e.result.message;
    expect_relative(e.rotation(0), t * l / (kG * ix), "torsion T l / (G Ix)");
  }
}

TEST(Static, ClampedClampedCentreStiffness) {
  // Span L = 1.2 m between two clamps; a centre body carried by two beams of L/2.
  const double span = 1.2, d = 0.02, p = 1e-2;
  const double i = M_PI * std::pow(d, 4) / 64;
  const Equilibrium e = solve(R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"rod": {"shape": "circle", "diameter": 0.02}},
    "bodies": [{"name": "mid", "mass": 1.0, "inertia": [1e-3, 1e-3, 1e-3], "position": [0.6, 0, 0]}],
    "beams": [
      {"name": "left", "body1": "ground", "body2": "mid", "point1": [0, 0, 0], "point2": [0.6, 0, 0],
       "point3": [0, 1, 0], "material": "steel", "section": "rod"},
      {"name": "right", "body1": "mid", "body2": "ground", "point1": [0.6, 0, 0], "point2": [1.2, 0, 0],
       "point3": [0.6, 1, 0], "material": "steel", "section": "rod"}],
    "loads": [{"type": "force", "body": "mid", "value": [0, -1e-2, 0]}]})");
  ASSERT_TRUE(e.result.ok) << e.result.message;
  expect_relative(p / -e.displacement(1), 192 * kE * i / std::pow(span, 3),
                  "clamped-clamped 192 E I / L^3");
  EXPECT_LT(std::abs(e.rotation(2)), 1e-12);  // symmetric: the centre does not turn
}

TEST(Static, NoLoadsLeaveTheSceneWhereItIs) {
  const Equilibrium e = solve(cantilever(1.0, kSquare, "[]"));
  ASSERT_TRUE(e.result.ok) << e.result.message;
  EXPECT_EQ(e.result.iterations, 0);
  EXPECT_EQ(e.displacement.norm(), 0.0);
}

// Long chains are ill-conditioned (|K| |x| >> |f|) but not singular: 1,000 and 3,000 segments
// (6,000 and 18,000 unknowns) once failed as "a body or mechanism is free to move".
TEST(Static, LongChainsAreNotMistakenForMechanisms) {
  const double closed = 1.0 / (3.0 * kE * 0.01 * 1e-6 / 12.0);
  for (int segments : {1000, 3000}) {
    const Model model = testing::scene_from_json(testing::reference_cantilever(segments));
    Data data(model);
    const StaticResult r = solve_static(model, StaticOptions{}, data);
    ASSERT_TRUE(r.ok) << segments << ": " << r.message;
    EXPECT_EQ(r.singular_directions, 0);
    const int tip = model.free_bodies[0];
    const double deflection = -data.pose[tip].u.y();
    std::printf("%d segments: %d iterations, tip deflection %.10e, linear %.10e\n", segments,
                r.iterations, deflection, closed);
    // Short of the linear deflection by (deflection / l)^2 = 3.6e-6, to 10 % of that.
    EXPECT_NEAR(1.0 - deflection / closed, closed * closed, 0.1 * closed * closed) << segments;
  }
}

}  // namespace
}  // namespace beamrail
