// Options a C++ caller gets wrong are refused before the static, modal or buckling analysis runs
// (StaticOptions, ModalOptions, BucklingOptions::IsValid), the reason naming the option; the
// defaults are valid. (Transient options: transient_limits_test.)
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include "core/analysis/buckling_analysis.hpp"
#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/static_analysis.hpp"
#include "tests/support/transient_run.hpp"

namespace beamrail {
namespace {

using testing::scene_from_json;

// A steel cantilever (1 m, 10 mm square) with a 1 kg tip body under an end load.
Model cantilever() {
  return scene_from_json(R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.1e10, "density": 7850}},
    "sections": {"sq10": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [{"name": "tip", "mass": 1.0, "inertia": [0.001, 0.001, 0.001],
                "position": [1, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel",
               "section": "sq10"}],
    "loads": [{"type": "force", "body": "tip", "value": [-100, 0, 0]}]})");
}

template <typename Options, typename Result>
void expect_refused(const char* named, const std::function<void(Options&)>& spoil,
                    const std::function<Result(const Options&)>& solve) {
  Options o;
  std::string why;
  ASSERT_TRUE(o.IsValid(&why)) << why;
  spoil(o);
  EXPECT_FALSE(o.IsValid(&why)) << named;
  EXPECT_NE(why.find(named), std::string::npos) << named << ": " << why;
  const Result r = solve(o);
  EXPECT_FALSE(r.ok) << named;
  EXPECT_NE(r.message.find(named), std::string::npos) << r.message;
}

TEST(AnalysisOptions, StaticModalAndBucklingRefuseOptionsThatCannotRun) {
  const Model model = cantilever();
  Data data(model);
  const std::function<StaticResult(const StaticOptions&)> statics = [&](const StaticOptions& o) {
    return solve_static(model, o, data);
  };
  expect_refused<StaticOptions, StaticResult>(
      "max_iterations", [](StaticOptions& o) { o.max_iterations = 0; }, statics);
  expect_refused<StaticOptions, StaticResult>(
      "tolerance", [](StaticOptions& o) { o.tolerance = NAN; }, statics);
  expect_refused<StaticOptions, StaticResult>(
      "load_steps", [](StaticOptions& o) { o.load_steps = -2; }, statics);
  expect_refused<StaticOptions, StaticResult>(
      "max_seconds", [](StaticOptions& o) { o.max_seconds = -1.0; }, statics);
  const std::function<ModalResult(const ModalOptions&)> modal = [&](const ModalOptions& o) {
    return solve_modal(model, o, data);
  };
  expect_refused<ModalOptions, ModalResult>(
      "modes", [](ModalOptions& o) { o.modes = 0; }, modal);
  expect_refused<ModalOptions, ModalResult>(
      "load_factor", [](ModalOptions& o) { o.load_factor = INFINITY; }, modal);
  expect_refused<ModalOptions, ModalResult>(
      "time", [](ModalOptions& o) { o.time = NAN; }, modal);
  const std::function<BucklingResult(const BucklingOptions&)> buckling =
      [&](const BucklingOptions& o) { return solve_buckling(model, model, o, data); };
  expect_refused<BucklingOptions, BucklingResult>(
      "modes", [](BucklingOptions& o) { o.modes = -1; }, buckling);
  expect_refused<BucklingOptions, BucklingResult>(
      "max_seconds", [](BucklingOptions& o) { o.max_seconds = NAN; }, buckling);
}

}  // namespace
}  // namespace beamrail
