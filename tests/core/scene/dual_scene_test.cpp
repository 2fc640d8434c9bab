// The scene built on hyper-dual numbers (core/scene/scene_loader.hpp load_dual_scene): forward-mode
// automatic differentiation through the scene -> model build. On a scene with every kind of number
// a design variable may address (section dimensions of every shape and custom constants, material
// constants, body mass, inertia, position and orientation, attachment points, damping, a rail's
// floor and travel, load values and points, a follower load, load time functions, gravity, a
// joint's point, axis and compliance, segmented beams), the values are the double build's and the
// derivatives of every number of the model agree with extrapolated central differences of double
// builds; a pointer to a number the build does not differentiate is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/model/hyper_dual.hpp"
#include "core/model/model_numbers.hpp"
#include "core/scene/scene_loader.hpp"

namespace beamrail {
namespace {

const char* kScene = R"json({
  "gravity": [0.3, -0.2, -9.81],
  "materials": {"steel": {"E": 2.1e11, "G": 8.1e10, "density": 7850},
                "alu": {"E": 7e10, "G": 2.6e10, "density": 2700}},
  "sections": {"rect": {"shape": "rectangle", "width": 0.03, "height": 0.02},
               "disc": {"shape": "circle", "diameter": 0.025},
               "pipe": {"shape": "tube", "outer_diameter": 0.05, "wall": 0.004},
               "boxy": {"shape": "box", "width": 0.06, "height": 0.04, "wall": 0.003},
               "own": {"shape": "custom", "S": 4e-4, "Ix": 3e-8, "Iy": 2e-8, "Iz": 5e-8,
                       "Wy": 1e-6, "Wz": 2e-6}},
  "bodies": [
    {"name": "hub", "mass": 5, "inertia": [0.05, 0.06, 0.07, 0.001, -0.002, 0.003],
     "position": [0.5, 0.1, 1.0], "orientation": [0.9, 0.1, -0.2, 0.3720215]},
    {"name": "tip", "mass": 2, "inertia": [0.01, 0.012, 0.014], "position": [1.2, 0.3, 0.9]},
    {"name": "cart", "mass": 1.5, "inertia": [0.003, 0.003, 0.003], "position": [0.5, 0.1, 1.4]}],
  "beams": [
    {"name": "post", "body1": "ground", "body2": "hub", "point1": [0.5, 0.1, 0],
     "point2": [0.5, 0.1, 1.0], "point3": [1.5, 0.1, 0], "material": "steel",
     "section": "pipe", "segments": 3, "damping": 1e-4},
    {"name": "arm", "body1": "hub", "body2": "tip", "point1": [0.55, 0.12, 1.0],
     "point2": [1.2, 0.3, 0.9], "point3": [0.55, 1.12, 1.0], "material": "alu",
     "section": "boxy", "segments": 2},
    {"name": "brace", "body1": "ground", "body2": "tip", "point1": [1.2, 0.3, 0],
     "point2": [1.2, 0.3, 0.9], "point3": [2.2, 0.3, 0], "material": "steel", "section": "rect"},
    {"name": "stay", "body1": "ground", "body2": "hub", "point1": [0, 0.1, 1.0],
     "point2": [0.45, 0.1, 1.0], "point3": [0, 1.1, 1.0], "material": "alu", "section": "disc"},
    {"name": "link", "body1": "tip", "body2": "ground", "point1": [1.2, 0.3, 0.9],
     "point2": [1.2, 1.3, 0.9], "point3": [2.2, 0.3, 0.9], "material": "steel", "section": "own"}],
  "rails": [
    {"name": "guide", "type": "prismatic", "body1": "hub", "body2": "cart",
     "point1": [0.5, 0.1, 1.1], "point2": [0.5, 0.1, 1.4], "point3": [1.5, 0.1, 1.1],
     "material": "steel", "section": "rect", "min_length": 0.01, "travel": [0.05, 0.6]}],
  "joints": [
    {"name": "pin", "type": "revolute", "body1": "hub", "body2": "cart", "point": [0.5, 0.1, 1.3],
     "axis": [0.2, 1, 0.1], "relative_compliance": 1e-5}],
  "loads": [
    {"type": "force", "body": "tip", "value": [10, -20, 30], "point": [1.25, 0.3, 0.95],
     "time": {"type": "table", "t": [0, 1, 2], "v": [0, 1, 0.5]}},
    {"type": "torque", "body": "hub", "value": [1, 2, -3], "follows": true,
     "time": {"type": "harmonic", "frequency": 3, "phase": 0.2}}]})json";

// The study variables' kinds: one pointer per kind.
const std::vector<std::string> kPointers = {
    "/scene/gravity/2",
    "/scene/materials/steel/E",
    "/scene/materials/alu/G",
    "/scene/materials/steel/density",
    "/scene/sections/rect/width",
    "/scene/sections/disc/diameter",
    "/scene/sections/pipe/wall",
    "/scene/sections/boxy/height",
    "/scene/sections/own/Iz",
    "/scene/sections/own/Wy",
    "/scene/bodies/0/mass",
    "/scene/bodies/0/inertia/4",
    "/scene/bodies/1/inertia/1",
    "/scene/bodies/1/position/0",
    "/scene/bodies/0/orientation/1",
    "/scene/beams/0/damping",
    "/scene/beams/1/point2/2",
    "/scene/beams/1/point3/0",
    "/scene/beams/0/point1/1",
    "/scene/rails/0/min_length",
    "/scene/rails/0/travel/1",
    "/scene/rails/0/point2/2",
    "/scene/joints/0/point/0",
    "/scene/joints/0/axis/2",
    "/scene/joints/0/relative_compliance",
    "/scene/loads/0/value/1",
    "/scene/loads/0/point/2",
    "/scene/loads/1/value/0",
    "/scene/loads/0/time/t/1",
    "/scene/loads/0/time/v/2",
    "/scene/loads/1/time/frequency",
};

Json scene_json() { return Json::parse(kScene); }

Model build(const Json& scene) {
  Diagnostics diag;
  const auto m = load_scene(scene, Where{"s.json", ""} / "scene", diag);
  EXPECT_TRUE(m) << diag.format();
  return *m;
}

// The numbers of a model in a fixed order.
template <class S>
std::vector<S> numbers(const ModelT<S>& m) {
  std::vector<S> out;
  zip_numbers<double>(
      [&](const S& x) {
        out.push_back(x);
        return 0.0;
      },
      m);
  return out;
}

Json& at(Json& doc, const std::string& pointer) {
  return doc[Json::json_pointer(pointer.substr(std::string("/scene").size()))];
}

TEST(DualScene, ValuesAreTheDoubleBuildsAndDerivativesAgreeWithDifferences) {
  const Json scene = scene_json();
  const Model model = build(scene);
  const std::vector<double> values = numbers(model);
  double worst = 0.0;
  for (const std::string& pointer : kPointers) {
    Diagnostics diag;
    const auto dual = load_dual_scene(scene, Where{"s.json", ""} / "scene", {{pointer, 1.0}},
                                      model.segment_choices, diag);
    ASSERT_TRUE(dual) << pointer << ": " << diag.format();
    const std::vector<HyperDual> d = numbers(*dual);
    ASSERT_EQ(d.size(), values.size());
    // Central differences of double builds at steps s and s/2, extrapolated.
    Json copy = scene;
    const double x = at(copy, pointer).get<double>();
    const auto central = [&](double s) {
      at(copy, pointer) = x + s;
      const std::vector<double> up = numbers(build(copy));
      at(copy, pointer) = x - s;
      const std::vector<double> down = numbers(build(copy));
      std::vector<double> out(up.size());
      for (size_t k = 0; k < up.size(); ++k)
        out[k] = up[k] == down[k] ? 0.0 : (up[k] - down[k]) / (2 * s);
      return out;
    };
    const double s = 1e-3 * std::abs(x);
    const std::vector<double> a = central(s), b = central(s / 2);
    double largest = 0.0;  // the largest derivative of a number relative to the number
    for (size_t k = 0; k < values.size(); ++k)
      if (std::isfinite(values[k]) && values[k] != 0.0)
        largest = std::max(largest, std::abs(d[k].b * x / values[k]));
    ASSERT_GT(largest, 1e-3) << pointer << " moves no number of the model";
    double error = 0.0;
    size_t nonzero = 0;
    for (size_t k = 0; k < values.size(); ++k) {
      if (!std::isfinite(values[k])) {
        EXPECT_EQ(d[k].b, 0.0) << pointer << ", number " << k;
        continue;
      }
      // Equal but for the order of the sums in Eigen's products (vectorized for doubles; an
      // inverse inertia amplifies that by its condition; zeros left at 1e-13 by rounding).
      EXPECT_NEAR(d[k].v, values[k], 1e-12 * std::abs(values[k]) + 1e-12)
          << pointer << ", number " << k;
      const double reference = (4 * b[k] - a[k]) / 3;
      // Zeros of the exact model that rounding leaves at ~1e-16 (a frame's entries, an offset
      // along an axis): their differences are rounding over the step; both change by far less
      // than 1e-9 over the whole variable.
      if (std::abs(values[k]) < 1e-12) {
        EXPECT_LT(std::abs((d[k].b - reference) * x), 1e-9) << pointer << ", number " << k;
        continue;
      }
      // Relative to the number's own scale (a number's derivative of 1e-9 of it is rounding).
      const double scale = std::max(std::abs(values[k] / x), std::abs(reference));
      if (scale == 0.0) {
        EXPECT_EQ(d[k].b, 0.0) << pointer << ", number " << k;
        continue;
      }
      if (d[k].b != 0.0) ++nonzero;
      error = std::max(error, std::abs(d[k].b - reference) / scale);
    }
    std::printf("%-38s %4zu numbers move, largest difference %.1e of their scale\n",
                pointer.c_str(), nonzero, error);
    EXPECT_LT(error, 1e-7) << pointer;
    worst = std::max(worst, error);
  }
  std::printf("%zu pointers, %zu numbers each: derivatives within %.1e of the differences\n",
              kPointers.size(), values.size(), worst);
}

TEST(DualScene, APointerTheBuildDoesNotDifferentiateIsRefused) {
  const Json scene = scene_json();
  const Model model = build(scene);
  for (const std::string pointer :
       {"/scene/beams/0/segments", "/scene/bodies/0/name", "/scene/beams/9/point1/0"}) {
    Diagnostics diag;
    const auto dual = load_dual_scene(scene, Where{"s.json", ""} / "scene", {{pointer, 1.0}},
                                      model.segment_choices, diag);
    EXPECT_FALSE(dual) << pointer;
    EXPECT_NE(diag.format().find("not a number the scene's build differentiates"),
              std::string::npos)
        << diag.format();
  }
}

}  // namespace
}  // namespace beamrail
