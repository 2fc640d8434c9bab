// The warnings of the element laws' range (an element past the small-angle range, a carriage far
// out on a rail without a travel) watch every accepted step of every method, not only the output
// rows: a swing that goes past the range and back between two rows is warned of, with its peak
// and when it was reached. Closed forms: a disc twisting on a shaft (a linear torsion law, so
// theta = (w0 / W) sin(W t) at any amplitude) and a carriage pushed from rest on a spring.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/analysis/deformation_check.hpp"
#include "core/analysis/modal_step_bounds.hpp"
#include "core/analysis/transient.hpp"
#include "core/model/data.hpp"
#include "core/model/element_kinematics.hpp"
#include "tests/support/scene_builder.hpp"
#include "tests/support/scenes.hpp"
#include "tests/support/transient_run.hpp"

namespace beamrail {
namespace {

using testing::Scene;
using testing::simulate;
constexpr double kE = 2.1e11, kG = 8.0769e10, kPi = 3.14159265358979;
const std::vector<std::string> kMethods = {"auto", "modal", "bdf", "adams", "dirk", "erk"};

// The warnings that contain `what`.
std::vector<std::string> warnings_with(const TransientResult& r, const std::string& what) {
  std::vector<std::string> out;
  for (const std::string& w : r.warnings)
    if (w.find(what) != std::string::npos) out.push_back(w);
  return out;
}

// The number after `key` in `text` (NaN when absent).
double number_after(const std::string& text, const std::string& key) {
  const size_t at = text.find(key);
  return at == std::string::npos ? std::nan("") : std::atof(text.c_str() + at + key.size());
}

// The margins the modal method's steps resolve (core/analysis/modal_step_bounds.hpp), in
// configurations set by hand: a disc twisted theta on a 1 m shaft is 0.5 - theta from the
// small-angle warning, past it min(limit - theta, theta / 10); a carriage x from point 1 of a rail
// without a travel, 0.01 m at the start, is 0.1 - x from its warning, past it x / 10, and x - 0.004
// from its min_length while above it; the shaft's axial extent (1 m) is the other length margin.
TEST(RangeWarnings, TheMarginsToTheEdgesAreTheirClosedForms) {
  Scene s;
  s.material("steel", kE, kG).circle("rod", 0.02);
  s.body("disc", 1.0, Vec3(1e-4, 1e-4, 1e-4), Vec3(1, 0, 0));
  s.body("carriage", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(0.01, 0, 0));
  s.beam("shaft", "ground", "disc", Vec3::Zero(), Vec3(1, 0, 0), "steel", "rod");
  s.rail("guide", "prismatic", "ground", "carriage", Vec3::Zero(), Vec3(0.01, 0, 0), "steel",
         "rod");
  s.last_rail()["min_length"] = 0.004;
  const Model model = s.model();
  const double limit = angle_limit(rotation_measure(model.beams.at(0)));
  const int disc = testing::body_index(model, "disc");
  const int carriage = testing::body_index(model, "carriage");
  Data data(model);
  // The smallest margin over the elements, in length and in angle.
  const auto element_length_margin = [](const Model& m, const Data& d) {
    const std::vector<double> v = element_margins(m, d).length;
    return *std::min_element(v.begin(), v.end());
  };
  const auto element_angle_margin = [](const Model& m, const Data& d) {
    const std::vector<double> v = element_margins(m, d).angle;
    return *std::min_element(v.begin(), v.end());
  };
  EXPECT_NEAR(element_angle_margin(model, data), kSmallAngleLimit, 1e-12);
  EXPECT_NEAR(element_length_margin(model, data), 0.006, 1e-12);
  for (const double theta : {0.3, 0.7, 1.45}) {
    data.pose[disc].A = Eigen::AngleAxisd(theta, Vec3::UnitX()).toRotationMatrix();
    const double expected = theta < 0.5 ? 0.5 - theta : std::min(limit - theta, 0.1 * theta);
    EXPECT_NEAR(element_angle_margin(model, data), expected, 1e-9) << theta;
  }
  for (const double x : {0.003, 0.05, 0.2, 20.0}) {
    data.pose[carriage].u = Vec3(x - 0.01, 0, 0);
    const double expected =
        std::min({1.0, x < 0.1 ? 0.1 - x : 0.1 * x, x > 0.004 ? x - 0.004 : 1.0});
    EXPECT_NEAR(element_length_margin(model, data), expected, 1e-12) << x;
  }
}

// A disc of polar inertia 1e-4 on a 1 m massless steel shaft (10 mm square, G Ix / L = 114 N m)
// spun about the shaft at w0 twists theta = (w0 / W) sin(W t), W = sqrt(114 / 1e-4) = 1,068 rad/s.
// With the rows every half period the twist is zero at every row. At w0 = 0.8 W (0.8 rad) every
// method once reported the run without a warning; now each warns of about 0.8 rad near a quarter
// period. At 0.4 rad none warns.
TEST(RangeWarnings, ATwistPastTheSmallAngleRangeBetweenRowsIsWarnedOf) {
  const double ix = 1.406e-9;  // a 10 mm square's torsion constant [m^4]
  const double w = std::sqrt(kG * ix / 1e-4), half_period = kPi / w;
  for (const double amplitude : {0.8, 0.4}) {
    for (const std::string& method : kMethods) {
      Scene s;
      s.material("steel", kE, kG).custom("sq10", 1e-4, ix, 8.333e-10, 8.333e-10);
      s.body("disc", 1.0, Vec3(1e-4, 1e-2, 1e-2), Vec3(1, 0, 0));
      s.last_body()["angular_velocity"] = testing::vec(amplitude * w, 0, 0);
      s.beam("shaft", "ground", "disc", Vec3::Zero(), Vec3(1, 0, 0), "steel", "sq10");
      const auto run =
          simulate(s.model(), testing::range_options(method, 4 * half_period, half_period));
      ASSERT_TRUE(run.result.ok) << method << ": " << run.result.message;
      // The rows see no twist: the closed form is at its zeros there.
      double at_rows = 0.0;
      for (const auto& snap : run.samples) {
        const Vec4& q = snap.q[1];
        at_rows = std::max(at_rows, 2.0 * std::atan2(std::abs(q(1)), std::abs(q(0))));
      }
      EXPECT_LT(at_rows, 1e-4) << method;
      const auto warned = warnings_with(run.result, "small-angle range");
      const double peak = warned.empty() ? 0.0 : number_after(warned[0], "reached ");
      const double when = warned.empty() ? 0.0 : number_after(warned[0], "at t = ");
      std::printf("%.1f rad, %s: %ld steps, largest twist at the rows %.1e rad, %s\n", amplitude,
                  method.c_str(), run.result.stats.steps, at_rows,
                  warned.empty() ? "no warning" : warned[0].c_str());
      if (amplitude < 0.5) {
        EXPECT_TRUE(warned.empty()) << method;
        continue;
      }
      ASSERT_EQ(warned.size(), 1u) << method;
      EXPECT_NE(warned[0].find("beam \"shaft\""), std::string::npos) << method;
      // The largest twist of the accepted steps: at most the amplitude (the warning prints three
      // digits), at least the closed form's value a sixteenth of a period from its peak.
      EXPECT_LE(peak, 0.8005) << method;
      EXPECT_GE(peak, 0.8 * std::cos(kPi / 8)) << method;
      EXPECT_NEAR(peak, 0.8 * std::abs(std::sin(w * when)), 2e-3) << method;
    }
  }
}

// A carriage (1 kg) at rest 0.01 m from point 1 of a rail without a travel, on a spring of
// 144 N/m (w = 12 rad/s), pushed from t = 0 by 14.4 N along the rail: x = 0.01 + 0.1 (1 - cos(w
// t)), out to 0.21 m (21 times its initial distance) at pi / w = 0.2618 s and back at every row
// (one per period). Every method warns that it went about 21 times its initial distance.
TEST(RangeWarnings, ACarriageFarOutOnARailWithoutATravelBetweenRowsIsWarnedOf) {
  const double area = kPi * 0.01 * 0.01, e_soft = 144.0 * 0.01 / area;
  const double period = 2 * kPi / 12.0;
  for (const std::string& method : kMethods) {
    Scene s;
    s.material("steel", kE, kG).material("soft", e_soft, e_soft / 2.6).circle("rod", 0.02);
    s.body("carriage", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(0.01, 0, 0));
    s.rail("guide", "prismatic", "ground", "carriage", Vec3::Zero(), Vec3(0.01, 0, 0), "steel",
           "rod");
    s.beam("spring", "ground", "carriage", Vec3::Zero(), Vec3(0.01, 0, 0), "soft", "rod");
    s.force("carriage", Vec3(14.4, 0, 0));
    TransientOptions o = testing::range_options(method, 2 * period, period);
    o.integrator.rtol = 1e-6;
    o.integrator.atol = 1e-9;
    const auto run = simulate(s.model(), o);
    ASSERT_TRUE(run.result.ok) << method << ": " << run.result.message;
    double at_rows = 0.0;
    for (const auto& snap : run.samples) at_rows = std::max(at_rows, snap.c[1].x());
    EXPECT_LT(at_rows, 0.0101) << method;
    const auto warned = warnings_with(run.result, "times its initial distance");
    const double ratio = warned.empty() ? 0.0 : number_after(warned[0], "went ");
    const double when = warned.empty() ? 0.0 : number_after(warned[0], "at t = ");
    std::printf("%s: %ld steps, farthest at the rows %.4f m, %s\n", method.c_str(),
                run.result.stats.steps, at_rows, warned.empty() ? "no warning" : warned[0].c_str());
    ASSERT_EQ(warned.size(), 1u) << method;
    EXPECT_LE(ratio, 21.05) << method;
    EXPECT_GE(ratio, 1.0 + 10.0 * (1.0 + std::cos(kPi / 8))) << method;
    EXPECT_NEAR(ratio, 1.0 + 10.0 * (1.0 - std::cos(12.0 * when)), 0.05) << method;
  }
}

// How far a mode moves an element (element_reach), by hand: a 1 kg bob 0.5 m below its rail's
// point 2 (on the rail's axis, x), the rail from the ground's origin to (0.3, 0, 0). A unit turn
// about the axis (the centre moving (0, 0.5, 0) with it) leaves point 2 where it is and turns the
// element 1 rad, which a cylindrical rail's angle measure does not see (it turns freely there):
// 0 for it, 1 for a prismatic one. A unit turn about z about the bob's centre moves point 2 by
// (0, 0, 1) x (0, 0, 0.5) = 0: length 0, angle 1 for both. A unit slide along x moves it 1, no
// angle. And the longest step over which those paths cannot carry the element across a quarter
// of its margin m unseen (modal_slow_edge_step): sqrt(8 m / 4 / d), d how far the modes'
// accelerations move it together.
TEST(RangeWarnings, AModeMovesAnElementByItsEndsRelativeMotion) {
  for (const std::string type : {"cylindrical", "prismatic"}) {
    Scene s;
    s.material("steel", kE, kG).circle("rod", 0.02);
    s.body("bob", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(0.3, 0, -0.5));
    s.rail("hinge", type, "ground", "bob", Vec3::Zero(), Vec3(0.3, 0, 0), "steel", "rod");
    const Model model = s.model();
    const Data data(model);
    Eigen::MatrixXd phi = Eigen::MatrixXd::Zero(6, 3);
    phi.col(0) << 0, 0.5, 0, 1, 0, 0;  // a turn about the rail's axis
    phi.col(1) << 0, 0, 0, 0, 0, 1;    // a turn about z about the centre
    phi.col(2) << 1, 0, 0, 0, 0, 0;    // a slide along the rail
    const ElementReach reach = element_reach(model, data, phi);
    ASSERT_EQ(reach.length.rows(), 3);
    ASSERT_EQ(reach.length.cols(), 1);
    const double about_axis = type == "cylindrical" ? 0.0 : 1.0;
    EXPECT_NEAR(reach.length(0, 0), 0.0, 1e-12) << type;
    EXPECT_NEAR(reach.angle(0, 0), about_axis, 1e-12) << type;
    EXPECT_NEAR(reach.length(1, 0), 0.0, 1e-12) << type;
    EXPECT_NEAR(reach.angle(1, 0), 1.0, 1e-12) << type;
    EXPECT_NEAR(reach.length(2, 0), 1.0, 1e-12) << type;
    EXPECT_NEAR(reach.angle(2, 0), 0.0, 1e-12) << type;
    EXPECT_NEAR(reach.largest(1, 1), 1.0, 1e-12) << type;
    // Three rigid modes accelerating at 2, -3 and 5 (units per s^2), margins 1 m and 0.4 rad:
    // together they slide the carriage 5 and turn it (2, 0, -3), of which a cylindrical rail
    // sees (0, 0, -3) (angle 3), a prismatic one all (sqrt 13): the angle decides.
    const Eigen::ArrayXd lambda = Eigen::ArrayXd::Zero(3);
    const Eigen::ArrayXd accel = (Eigen::ArrayXd(3) << 2.0, -3.0, 5.0).finished();
    const double angle = type == "cylindrical" ? 3.0 : std::sqrt(13.0);
    EXPECT_NEAR(modal_slow_edge_step(lambda, accel, phi, reach, {1.0}, {0.4}, 10.0, 0.25),
                std::min(std::sqrt(8.0 * 0.25 * 1.0 / 5.0), std::sqrt(8.0 * 0.25 * 0.4 / angle)),
                1e-12)
        << type;
    // A step already that short is left as it is; an oscillating mode the step does not resolve
    // (lambda h^2 above (pi / 8)^2) is not counted: only the slide's 5 remains in length.
    EXPECT_EQ(modal_slow_edge_step(lambda, accel, phi, reach, {0.1}, {0.4}, 0.01, 0.25), 0.01);
    const Eigen::ArrayXd turning = (Eigen::ArrayXd(3) << 1e4, 1e4, 0.0).finished();
    EXPECT_NEAR(modal_slow_edge_step(turning, accel, phi, reach, {0.1}, {0.4}, 1.0, 0.25),
                std::sqrt(8.0 * 0.25 * 0.1 / 5.0), 1e-12)
        << type;
    // Two modes that slide it opposite ways at the same rate do not move it together.
    Eigen::MatrixXd pair = Eigen::MatrixXd::Zero(6, 2);
    pair.col(0) = phi.col(2);
    pair.col(1) = -phi.col(2);
    EXPECT_EQ(modal_slow_edge_step(Eigen::ArrayXd::Zero(2), Eigen::ArrayXd::Constant(2, 5.0), pair,
                                   reach, {0.1}, {0.4}, 1.0, 0.25),
              1.0);
  }
}

}  // namespace
}  // namespace beamrail
