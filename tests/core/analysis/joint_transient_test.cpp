// Joints in the transient methods "auto" and "modal" (core/analysis/auto_integrator.hpp,
// modal_integrator.hpp): their error against a tight explicit run (the work-precision study's
// measure, as tests/core/analysis/transient_auto_test.cpp), on scenes whose joints add penalty
// modes far above the structure's.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "tests/support/transient_run.hpp"

namespace beamrail {
namespace {

using testing::options;
using testing::run_error;
using testing::scene_from_json;
using testing::simulate;
using testing::TransientRun;

TransientRun run_with(const Model& model, const std::string& method, double t_end,
                      double output_step, double rtol) {
  TransientOptions o = options(t_end, output_step, rtol, 1e-2 * rtol);
  o.integrator.method = *method_from_name(method);
  if (method == "erk") o.integrator.table = "VERNER_8_5_6";
  return simulate(model, o);
}

// A massless 1 m steel cantilever (10 mm square) with a 1 kg tip; a 2 kg weight welded to the
// tip by a fixed joint (relative compliance 1e-3) 0.1 m beyond it; a force on the weight ramped up
// over 5 ms (a step would set the joint's penalty modes ringing, which a tight reference must
// then resolve: millions of steps).
const char* kWelded = R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [{"name": "tip", "mass": 1.0, "inertia": [1e-4, 1e-4, 1e-4], "position": [1, 0, 0]},
               {"name": "weight", "mass": 2.0, "inertia": [2e-3, 2e-3, 2e-3], "position": [1.1, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq"}],
    "joints": [{"name": "weld", "type": "fixed", "body1": "tip", "body2": "weight",
                "point": [1.05, 0, 0], "relative_compliance": 1e-3}],
    "loads": [{"type": "force", "body": "weight", "value": [0, -3, 1],
               "time": {"type": "ramp", "from": 0.0, "to": 0.005}}]})";

// The same cantilever with a 0.5 kg bob 0.2 m below its tip on a revolute joint about z: a force
// on the bob ramped up over 5 ms swings it about the joint (a mechanism the joint allows, some
// 0.006 rad in 50 ms) and bends the cantilever in and out of its plane.
const char* kHingedBob = R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [{"name": "tip", "mass": 1.0, "inertia": [1e-4, 1e-4, 1e-4], "position": [1, 0, 0]},
               {"name": "bob", "mass": 0.5, "inertia": [1e-3, 1e-3, 1e-3], "position": [1, -0.2, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq"}],
    "joints": [{"name": "hinge", "type": "revolute", "body1": "tip", "body2": "bob",
                "point": [1, 0, 0], "axis": [0, 0, 1], "relative_compliance": 1e-3}],
    "loads": [{"type": "force", "body": "bob", "value": [0.5, 0, 0.2],
               "time": {"type": "ramp", "from": 0.0, "to": 0.005}}]})";

TEST(JointTransient, AutoAndModalFollowTheirToleranceWithJoints) {
  struct Case {
    const char* label;
    const char* scene;
    double t_end;
  } cases[] = {{"cantilever with a welded weight", kWelded, 0.05},
               {"bob hinged to a cantilever", kHingedBob, 0.05}};
  for (const Case& c : cases) {
    const Model model = scene_from_json(c.scene);
    const TransientRun reference = run_with(model, "bdf", c.t_end, 1e-3, 1e-11);
    ASSERT_TRUE(reference.result.ok) << reference.result.message;
    const TransientRun check = run_with(model, "bdf", c.t_end, 1e-3, 1e-10);
    ASSERT_TRUE(check.result.ok) << check.result.message;
    std::printf("%s: bdf reference at rtol 1e-11, %ld steps; at rtol 1e-10 it differs by %.2e\n",
                c.label, reference.result.stats.steps, run_error(model, check, reference));
    for (const char* method : {"auto", "modal"}) {
      for (double rtol : {1e-5, 1e-7}) {
        const TransientRun run = run_with(model, method, c.t_end, 1e-3, rtol);
        ASSERT_TRUE(run.result.ok) << c.label << ", " << method << ": " << run.result.message;
        const double e = run_error(model, run, reference);
        std::printf("  %s, rtol %.0e: error %.2e = %.3f rtol, %ld steps, %ld phases\n", method,
                    rtol, e, e / rtol, run.result.stats.steps, run.result.phase_count);
        for (const MethodPhase& p : run.result.phases)
          std::printf("    t = %.4f s: %s: %s\n", p.t, p.method.c_str(), p.reason.c_str());
        EXPECT_LT(e, 10 * rtol) << c.label << ", " << method << ", rtol " << rtol;
      }
    }
  }
}

}  // namespace
}  // namespace beamrail
