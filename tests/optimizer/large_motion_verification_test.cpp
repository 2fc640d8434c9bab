// An auto run that relinearizes verifies itself by default ("verify": "auto"): where bodies turn
// past the relinearization limit the motion is no small one about a configuration, and the error
// can grow far past rtol with no other sign (docs/transient_measurements.md "Large motions verify
// themselves"). The scene is the one an adversarial review found: an L-frame, a 1 m steel
// cantilever in 5 segments whose 1 kg tip carries a 0.6 m leg in 3 segments down to a 2 kg foot,
// the tip started at (0, 2, 1) m/s under a constant 2 N, for 0.5 s.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/support/l_frame.hpp"
#include "tests/support/study_runs.hpp"

namespace beamrail {
namespace {

using Json = nlohmann::json;
using testing::l_frame;
using testing::load_json;
using testing::read_table;
using testing::Table;
using testing::warns_off_tolerance;

// The largest distance between the runs' scene-body centres [m], the largest motion of a
// reference centre [m], the largest angle between their orientations [rad] and the largest angle
// a reference body turned along its rows [rad].
struct Deviation {
  double centres = 0.0, motion = 0.0, angle = 0.0, turned = 0.0;
};

std::array<double, 4> quaternion(const Table& t, size_t row, const std::string& body) {
  std::array<double, 4> q{};
  for (int k = 0; k < 4; ++k) q[k] = std::stod(t.at(row, body + ".q" + std::to_string(k)));
  return q;
}

// The angle of the rotation between two orientations (Euler parameters) [rad].
double angle_between(const std::array<double, 4>& a, const std::array<double, 4>& b) {
  // The relative rotation a^-1 b: its scalar part and the norm of its vector part.
  const double w = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
  const double x = a[0] * b[1] - a[1] * b[0] - a[2] * b[3] + a[3] * b[2];
  const double y = a[0] * b[2] + a[1] * b[3] - a[2] * b[0] - a[3] * b[1];
  const double z = a[0] * b[3] - a[1] * b[2] + a[2] * b[1] - a[3] * b[0];
  return 2.0 * std::atan2(std::sqrt(x * x + y * y + z * z), std::abs(w));
}

Deviation deviation(const Table& run, const Table& reference) {
  Deviation d;
  for (const std::string body : {"tip", "foot"}) {
    double turned = 0.0;
    for (size_t i = 0; i < reference.rows.size() && i < run.rows.size(); ++i) {
      double distance = 0.0, moved = 0.0;
      for (const char* axis : {".x", ".y", ".z"}) {
        const double r = std::stod(reference.at(i, body + axis));
        distance += std::pow(std::stod(run.at(i, body + axis)) - r, 2);
        moved += std::pow(r - std::stod(reference.at(0, body + axis)), 2);
      }
      d.centres = std::max(d.centres, std::sqrt(distance));
      d.motion = std::max(d.motion, std::sqrt(moved));
      d.angle = std::max(d.angle,
                         angle_between(quaternion(run, i, body), quaternion(reference, i, body)));
      if (i > 0)
        turned += angle_between(quaternion(reference, i - 1, body), quaternion(reference, i, body));
    }
    d.turned = std::max(d.turned, turned);
  }
  return d;
}

// A deviation in multiples of its tolerance, as verify weighs it: the centres against
// rtol x + atol (x the largest motion), the orientations against rtol max(turned, 1 rad) + atol.
struct Weighed {
  double centres = 0.0, orientations = 0.0;
};

Weighed weigh(const Deviation& d, double rtol, double atol) {
  return {d.centres / (rtol * d.motion + atol), d.angle / (rtol * std::max(d.turned, 1.0) + atol)};
}

// The run `name`'s deviation from the reference run's.
Deviation deviation_of(const std::filesystem::path& dir, const std::string& name) {
  return deviation(read_table(dir / name / "swing.timeseries.csv"),
                   read_table(dir / "reference/swing.timeseries.csv"));
}

class LargeMotionVerification : public testing::StudyRuns {};

// At rtol 1e-5 (atol 9e-9) auto relinearizes hundreds of times and ends 21 times its tolerance off
// in the centres and 98 times in the orientations against Verner at rtol 1e-10 (measured
// 2026-11-30); its rerun at rtol 1e-6 estimates 21 and 98, and the run warns. Before, only a
// warning of the model (the beams' axial forces) was given.
TEST_F(LargeMotionVerification, AnAutoRunThatRelinearizesVerifiesItself) {
  const double rtol = 1e-5, atol = 9e-9;
  Json run = l_frame(1.0, {{"rtol", rtol}, {"atol", atol}});
  run["analyses"][0]["refine"] = false;  // the run itself, as it was (refined: below)
  run_ok(write_study("run.json", run), "run");
  run_ok(write_study("reference.json", l_frame(1.0, {{"method", "erk"},
                                                     {"table", "VERNER_8_5_6"},
                                                     {"rtol", 1e-10},
                                                     {"atol", 1e-12}})),
         "reference");
  const Json summary = load_json(dir_ / "run/summary.json");
  const Json& a = summary["analyses"][0];
  const Json& v = a["verification"];
  ASSERT_TRUE(v.is_object()) << summary.dump(2);
  const Deviation d = deviation_of(dir_, "run");
  const auto [centres, orientations] = weigh(d, rtol, atol);
  std::printf(
      "%ld phases; against Verner at rtol 1e-10: centres %.3g m (%.1f times their tolerance), "
      "orientations %.3g rad (%.1f times; %.2f rad turned); the rerun: centres %.3g, "
      "orientations %.3g of the largest turn; %.2f s against the run's %.2f s\n",
      a["phase_count"].get<long>(), d.centres, centres, d.angle, orientations, d.turned,
      v["error"].get<double>(), v["rotation_error"].get<double>(), v["wall_seconds"].get<double>(),
      a["wall_seconds"].get<double>());
  EXPECT_EQ(summary["status"], "ok");
  EXPECT_GT(a["phase_count"].get<long>(), 1);
  // The run is off beyond 10 times its tolerance (if a change mends it, this test needs another
  // run that is off) ...
  EXPECT_GT(orientations, 10.0);
  // ... was verified by default, for relinearizing ...
  EXPECT_NE(v["reason"].get<std::string>().find("relinearized as bodies turned"), std::string::npos)
      << v["reason"];
  // ... and says so, with an estimate of the centres' error of the right size.
  EXPECT_TRUE(warns_off_tolerance(summary)) << summary.dump(2);
  const double estimated = v["error"].get<double>() * d.motion;
  EXPECT_GT(estimated, d.centres / 3.0);
  EXPECT_LT(estimated, 3.0 * d.centres);

  // By default ("refine") it is run again at rtol 1e-6, whose rerun at 1e-7 it is weighed
  // against: its centres within their tolerance, its orientations 15.3 times it against Verner
  // (its rerun estimates 11.1, and it warns that the refined run is not within the tolerance
  // asked either), each 6.6 and 16 times nearer than the first run's (100.5 and 20.6 times). The
  // orientations' figure moves with the step pattern: 10.5 measured on 2026-12-01, 21.6 while
  // the modal steps resolved the modes carrying 99 % of the motion (asserted at 4 times nearer
  // then), 15.3 again with the edge bounds that replaced that (2026-12-02); so 5 times nearer.
  run_ok(write_study("refined.json", l_frame(1.0, {{"rtol", rtol}, {"atol", atol}})), "refined");
  const Json refined = load_json(dir_ / "refined/summary.json");
  const Json& r = refined["analyses"][0];
  ASSERT_TRUE(r.contains("refinement")) << refined.dump(2);
  const auto [refined_centres, refined_orientations] =
      weigh(deviation_of(dir_, "refined"), rtol, atol);
  std::printf(
      "refined at rtol %.0e: centres %.1f and orientations %.1f times their tolerance against "
      "Verner; its rerun at %.0e: %.1f and %.1f\n",
      r["refinement"]["rtol"].get<double>(), refined_centres, refined_orientations,
      r["verification"]["rtol"].get<double>(), r["verification"]["tolerances"].get<double>(),
      r["verification"]["rotation_tolerances"].get<double>());
  EXPECT_DOUBLE_EQ(r["refinement"]["rtol"].get<double>(), 1e-6);
  EXPECT_EQ(r["refinement"]["first_run"]["rotation_tolerances"], v["rotation_tolerances"]);
  EXPECT_LT(refined_centres, 10.0);
  EXPECT_LT(refined_centres, centres / 5.0);
  EXPECT_LT(refined_orientations, orientations / 5.0);
  // The rerun's estimates, weighed against the tolerance asked, of the right size.
  const double rotation_estimate = r["verification"]["rotation_tolerances"].get<double>();
  EXPECT_GT(rotation_estimate, refined_orientations / 3.0);
  EXPECT_LT(rotation_estimate, 3.0 * refined_orientations);
  EXPECT_EQ(warns_off_tolerance(refined),
            rotation_estimate > 10.0 || r["verification"]["tolerances"].get<double>() > 10.0)
      << refined.dump(2);
}

// At a thousandth of the speed the motion stays small: one modal phase, no rerun.
TEST_F(LargeMotionVerification, ASmallMotionIsNotRerun) {
  run_ok(write_study("small.json", l_frame(1e-3, {{"rtol", 1e-5}, {"atol", 9e-12}})), "small");
  const Json summary = load_json(dir_ / "small/summary.json");
  const Json& a = summary["analyses"][0];
  EXPECT_EQ(summary["status"], "ok");
  EXPECT_EQ(a["phase_count"].get<long>(), 1) << a.dump(2);
  EXPECT_FALSE(a.contains("verification")) << a.dump(2);
}

}  // namespace
}  // namespace beamrail
