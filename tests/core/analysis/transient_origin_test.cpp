// A scene's motion does not depend on where it sits: the integrators' states hold the bodies'
// displacements from their initial centres (docs/model.md "Bodies"), weighted as the motion, and
// an element's chord adds them after its reference geometry (core/model/element_kinematics.hpp).
// Until 2026-12-01 the states held the absolute centres: a cantilever 300 m from the origin was
// held to rtol of 300 m and its rounded centres made the stiff rotary mode's forces noisy, so dirk
// at rtol 1e-8 took 9.0 million steps where it took 2,285 at the origin, and ended 840 rtol of its
// swing off, silent (docs/transient_measurements.md "Transient runs far from the origin").
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "tests/support/transient_run.hpp"

namespace beamrail {
namespace {

using testing::options;
using testing::scene_from_json;
using testing::simulate;
using testing::TransientRun;

// A steel cantilever in three segments along x from the ground point `at`, bodies of small rotary
// inertia (stiff rotary modes), swinging in y and sagging under gravity.
Model cantilever_at(const Vec3& at) {
  const auto point = [&](double x, double y) {
    return "[" + std::to_string(at.x() + x) + ", " + std::to_string(at.y() + y) + ", " +
           std::to_string(at.z()) + "]";
  };
  std::string bodies, beams;
  for (int i = 1; i <= 3; ++i) {
    const double x = i / 3.0;
    bodies += std::string(i > 1 ? ", " : "") + R"({"name": "b)" + std::to_string(i) +
              R"(", "mass": 0.3, "inertia": [1e-5, 1e-5, 1e-5], "position": )" + point(x, 0) +
              R"(, "velocity": [0, )" + std::to_string(0.01 * x) + ", 0]}";
    beams += std::string(i > 1 ? ", " : "") + R"({"name": "s)" + std::to_string(i) +
             R"(", "body1": ")" + (i == 1 ? std::string("ground") : "b" + std::to_string(i - 1)) +
             R"(", "body2": "b)" + std::to_string(i) + R"(", "point1": )" + point(x - 1 / 3.0, 0) +
             R"(, "point2": )" + point(x, 0) + R"(, "point3": )" + point(x, 1) +
             R"(, "material": "steel", "section": "sq"})";
  }
  return scene_from_json(R"({"gravity": [0, 0, -9.81],
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [)" + bodies +
                         R"(], "beams": [)" + beams + "]}");
}

// Every method, 300 m out along an oblique direction: the steps of the run at the origin (within
// 2 %) and its displacements within rtol of the motion, where before it took up to 3,500 times
// the steps (or ran out of the budget of 20 times, here) and ended far off.
TEST(TransientOrigin, ACantileverFarFromTheOriginMovesAsAtTheOrigin) {
  const Model near = cantilever_at(Vec3::Zero());
  const Model far = cantilever_at(Vec3(300.1, -200.3, 123.7));
  ASSERT_EQ(near.n_free(), 3);
  ASSERT_EQ(far.n_free(), 3);
  const double rtol = 1e-8;
  for (const char* method : {"bdf", "dirk", "erk", "auto"}) {
    TransientOptions o = options(0.02, 1e-3, rtol, 1e-4 * rtol);
    o.integrator.method = *method_from_name(method);
    o.integrator.max_steps = 1000000;
    const TransientRun a = simulate(near, o);
    ASSERT_TRUE(a.result.ok) << method << ": " << a.result.message;
    o.integrator.max_steps = 20 * a.result.stats.steps;
    const TransientRun b = simulate(far, o);
    ASSERT_TRUE(b.result.ok) << method << ": " << b.result.message;
    ASSERT_EQ(a.samples.size(), b.samples.size());
    double error = 0.0, motion = 0.0;
    for (size_t k = 0; k < a.samples.size(); ++k)
      for (int body : near.free_bodies) {
        motion = std::max(motion, a.samples[k].pose[body].u.norm());
        error = std::max(error, (a.samples[k].pose[body].u - b.samples[k].pose[body].u).norm());
      }
    std::printf("%s: %ld steps at the origin, %ld 300 m out; the runs %.2e of the motion apart\n",
                method, a.result.stats.steps, b.result.stats.steps, error / motion);
    EXPECT_LT(std::abs(b.result.stats.steps - a.result.stats.steps), 0.02 * a.result.stats.steps)
        << method;
    EXPECT_LT(error, rtol * motion) << method;
  }
}

}  // namespace
}  // namespace beamrail
