// "segments": "auto" (core/scene/auto_segments.hpp): the rule's model of a beam is the model the
// scene builds (its frequencies against the full modal analysis), the count it picks meets the
// target against Euler-Bernoulli's closed form and is the smallest that does, a band checks the
// higher modes, the choice carries over to a frame, and bad input is refused with its pointer.
#include "core/scene/auto_segments.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "core/analysis/modal_analysis.hpp"
#include "core/scene/scene_loader.hpp"
#include "tests/support/scene_builder.hpp"

namespace beamrail {
namespace {

using testing::Scene;
constexpr double kE = 2.1e11, kG = 8.0769e10, kRho = 7850.0;

// A clamped-free beam of length `length` along x from the ground to a body that carries only
// the beam's own mass; `segments` is an integer or "auto". The section is slender (radius of
// gyration 0.3 mm): the rotary inertia moves the first three frequencies from Euler-Bernoulli's by
// less than 1e-6, so that the closed form is the chain's limit.
Scene cantilever(double length, const Json& segments) {
  Scene s;
  s.material("steel", kE, kG, kRho).custom("sec", 2e-4, 4e-11, 2e-11, 8e-11);
  s.body("tip", 1.0, Vec3(1, 1, 1), Vec3(length, 0, 0));
  s.last_body().erase("mass");
  s.last_body().erase("inertia");
  s.beam("arm", "ground", "tip", Vec3(0, 0, 0), Vec3(length, 0, 0), "steel", "sec");
  s.last_beam()["segments"] = segments;
  return s;
}

std::vector<double> elastic_frequencies(const Model& m, int modes) {
  Data data(m);
  ModalOptions options;
  options.modes = modes;
  const ModalResult r = solve_modal(m, options, data);
  EXPECT_TRUE(r.ok) << r.message;
  std::vector<double> f;
  for (const Mode& mode : r.modes)
    if (mode.kind == Mode::Kind::kElastic) f.push_back(mode.frequency_hz);
  return f;
}

UniformBeam beam_of(double length) {
  UniformBeam b;
  b.length = length;
  b.ei[0] = kE * 2e-11, b.ei[1] = kE * 8e-11;
  b.rho_i[0] = kRho * 2e-11, b.rho_i[1] = kRho * 8e-11;
  b.rho_area = kRho * 2e-4;
  return b;
}

// Euler-Bernoulli's clamped-free frequencies (beta_k L)^2 / (2 pi L^2) sqrt(E I / rho S).
double euler_bernoulli(double length, double ei, int k) {
  static constexpr double kBetaL[] = {1.8751040687, 4.6940911330, 7.8547574382};
  return kBetaL[k] * kBetaL[k] / (2.0 * std::numbers::pi * length * length) *
         std::sqrt(ei / (kRho * 2e-4));
}

// The rule's chain is the scene's: every bending frequency of the beam in 6 segments, in both
// planes, is one of the full 3-D modal analysis's to 1e-9.
TEST(AutoSegments, TheRulesChainHasTheFrequenciesOfTheSceneItBuilds) {
  const Model m = cantilever(1.0, 6).model();
  const std::vector<double> full = elastic_frequencies(m, 30);
  for (int plane = 0; plane < 2; ++plane) {
    const std::vector<double> chain = cantilever_bending_frequencies(beam_of(1.0), plane, 6);
    ASSERT_EQ(chain.size(), 12u);
    for (size_t k = 0; k < 4; ++k) {
      double closest = 1e300;
      for (double f : full) closest = std::min(closest, std::abs(f - chain[k]) / chain[k]);
      EXPECT_LT(closest, 1e-9) << "plane " << plane << " mode " << k + 1 << ": " << chain[k];
    }
  }
}

// The lowest frequencies of a longer chain (shift-invert Lanczos from 33 segments on) are the
// scene's, from the full modal analysis of the beam in 40 segments, to 1e-9. (Longer chains of
// this slender beam are ill-conditioned: at 200 segments the dense solver of every eigenvalue, the
// shift-invert one and the 3-D analysis differ by up to 1e-7, rounding relative to the largest
// eigenvalue, of the segments' rotary inertia; far below the differences the rule estimates from.)
TEST(AutoSegments, TheLowestFrequenciesOfALongChainAreTheScenes) {
  const std::vector<double> full = elastic_frequencies(cantilever(2.0, 40).model(), 12);
  for (int plane = 0; plane < 2; ++plane) {
    const std::vector<double> few = cantilever_bending_frequencies(beam_of(2.0), plane, 40, 4);
    ASSERT_EQ(few.size(), 4u);
    for (int k = 0; k < 4; ++k) {
      double closest = 1e300;
      for (double f : full) closest = std::min(closest, std::abs(f - few[k]) / few[k]);
      EXPECT_LT(closest, 1e-9) << "plane " << plane << " mode " << k + 1 << ": " << few[k];
    }
  }
}

// The chain converges at order 2 to Euler-Bernoulli's first frequency (printed); the rotary
// inertia of this slender beam shifts the limit by ~1e-6 only.
TEST(AutoSegments, TheChainConvergesAtOrderTwo) {
  const double exact = euler_bernoulli(2.0, kE * 2e-11, 0);
  double previous = 0.0;
  for (long n : {8, 16, 32, 64}) {
    const double e = std::abs(cantilever_bending_frequencies(beam_of(2.0), 0, n)[0] / exact - 1);
    if (previous > 0.0) {
      const double order = std::log2(previous / e);
      std::printf("n = %3ld: first-frequency error %.3e, observed order %.3f\n", n, e, order);
      EXPECT_NEAR(order, 2.0, 0.1);
    }
    previous = e;
  }
}

// For each target, the count "auto" picks gives the first frequency within the target of the
// closed form, and one ladder step fewer does not: the smallest count that does.
TEST(AutoSegments, TheCountMeetsTheTargetAndIsTheSmallestThatDoes) {
  static constexpr long kLadder[] = {1,  2,  3,  4,  5,  6,  8,  10, 12, 14,  16, 20,
                                     24, 28, 32, 40, 48, 56, 64, 80, 96, 112, 128};
  const double exact = euler_bernoulli(2.0, kE * 2e-11, 0);
  long last = 0;
  for (double target : {3e-2, 1e-2, 1e-3, 1e-4}) {
    Scene s = cantilever(2.0, "auto");
    s.j["segmentation"] = {{"frequency_error", target}};
    const Model m = s.model();
    ASSERT_EQ(m.segment_choices.size(), 1u);
    const SegmentChoice& c = m.segment_choices[0];
    const double error = std::abs(elastic_frequencies(m, 1)[0] / exact - 1);
    const long* at = std::find(std::begin(kLadder), std::end(kLadder), c.segments);
    ASSERT_NE(at, std::end(kLadder));
    ASSERT_NE(at, std::begin(kLadder));
    const double fewer =
        std::abs(elastic_frequencies(cantilever(2.0, *(at - 1)).model(), 1)[0] / exact - 1);
    std::printf("target %.0e: %ld segments, error %.3e (estimated %.3e); %ld segments: %.3e\n",
                target, c.segments, error, c.estimated_error, *(at - 1), fewer);
    EXPECT_TRUE(c.reached);
    EXPECT_LE(error, target);
    EXPECT_GT(fewer, target);
    EXPECT_NEAR(c.estimated_error / error, 1.0, 0.05);  // the estimate is the error
    EXPECT_GT(c.segments, last);
    last = c.segments;
  }
}

// With a band, every bending frequency below it is checked: with the band 10 % above the third
// clamped-free frequency, the first three are within the target of their closed forms (and need
// more segments than the first alone).
TEST(AutoSegments, ABandChecksEveryFrequencyBelowIt) {
  const double f3 = euler_bernoulli(2.0, kE * 2e-11, 2);
  Scene s = cantilever(2.0, "auto");
  s.j["segmentation"] = {{"frequency_error", 1e-3}, {"max_frequency_hz", 1.1 * f3}};
  const Model m = s.model();
  ASSERT_EQ(m.segment_choices.size(), 1u);
  const SegmentChoice& c = m.segment_choices[0];
  Scene first = cantilever(2.0, "auto");
  first.j["segmentation"] = {{"frequency_error", 1e-3}};
  const long without = first.model().segment_choices[0].segments;
  // Plane 0 (E Iy, the weaker) has modes 1-3 in the band; plane 1 (4x stiffer: 2x the
  // frequencies) its first two.
  EXPECT_EQ(c.frequencies_checked, 3);
  EXPECT_GT(c.segments, without);
  const std::vector<double> f = elastic_frequencies(m, 8);
  for (int k = 0; k < 3; ++k) {
    const double exact = euler_bernoulli(2.0, kE * 2e-11, k);
    double closest = 1e300;
    for (double x : f) closest = std::min(closest, std::abs(x / exact - 1));
    std::printf("band to %.1f Hz: %ld segments (first only: %ld); frequency %d error %.3e\n",
                1.1 * f3, c.segments, without, k + 1, closest);
    EXPECT_LE(closest, 1e-3);
  }
}

// A portal frame (two 3 m columns, a 4 m girder, all "auto" at 1e-3 with the band 5 % above the
// frame's third frequency): the frame's first three frequencies are within the target of the
// frame in 128 and 256 segments extrapolated at order 2. The rule sees each member alone; the
// band carries its guarantee over to the frame, whose third mode bends the girder beyond its own
// first frequency. (Without the band the third is 1.1e-3 off: printed.)
TEST(AutoSegments, AFrameOfAutoMembersMeetsTheTargetInItsBand) {
  const auto frame = [](const Json& segments, double band) {
    Scene s;
    s.material("steel", kE, kG, kRho).custom("col", 4e-3, 2e-5, 1e-5, 2e-5);
    s.custom("gir", 3e-3, 1e-5, 8e-6, 1.2e-5);
    for (const char* n : {"a", "b"}) {
      s.body(n, 1.0, Vec3(1, 1, 1), Vec3(0, 0, 3));
      s.last_body().erase("mass");
      s.last_body().erase("inertia");
    }
    s.last_body()["position"] = testing::vec(4, 0, 3);
    s.beam("left", "ground", "a", Vec3(0, 0, 0), Vec3(0, 0, 3), "steel", "col");
    s.last_beam()["segments"] = segments;
    s.beam("right", "ground", "b", Vec3(4, 0, 0), Vec3(4, 0, 3), "steel", "col");
    s.last_beam()["segments"] = segments;
    s.beam("girder", "a", "b", Vec3(0, 0, 3), Vec3(4, 0, 3), "steel", "gir");
    s.last_beam()["segments"] = segments;
    s.j["segmentation"] = {{"frequency_error", 1e-3}};
    if (band > 0.0) s.j["segmentation"]["max_frequency_hz"] = band;
    return s.model();
  };
  const std::vector<double> f128 = elastic_frequencies(frame(128, 0.0), 3);
  const std::vector<double> f256 = elastic_frequencies(frame(256, 0.0), 3);
  std::vector<double> reference(3);
  for (int k = 0; k < 3; ++k) reference[k] = f256[k] + (f256[k] - f128[k]) / 3.0;
  const Model banded = frame("auto", 1.05 * reference[2]), plain = frame("auto", 0.0);
  ASSERT_EQ(banded.segment_choices.size(), 3u);
  const std::vector<double> f = elastic_frequencies(banded, 3);
  const std::vector<double> g = elastic_frequencies(plain, 3);
  for (int k = 0; k < 3; ++k) {
    const double error = std::abs(f[k] / reference[k] - 1);
    std::printf(
        "frame mode %d: reference %.6f Hz; band: error %.3e (columns %ld, girder %ld "
        "segments); no band: %.3e (%ld, %ld)\n",
        k + 1, reference[k], error, banded.segment_choices[0].segments,
        banded.segment_choices[2].segments, std::abs(g[k] / reference[k] - 1),
        plain.segment_choices[0].segments, plain.segment_choices[2].segments);
    EXPECT_LE(error, 1e-3);
  }
}

// Counts given to load_scene are kept (and marked), whatever the target says.
TEST(AutoSegments, PinnedCountsAreKept) {
  Scene s = cantilever(2.0, "auto");
  const Json scene = s.j;
  Diagnostics diag;
  std::vector<SegmentChoice> pinned(1);
  pinned[0].beam = "arm";
  pinned[0].segments = 7;
  const auto m = load_scene(scene, {"test", ""}, diag, &pinned);
  ASSERT_TRUE(m) << diag.format();
  ASSERT_EQ(m->segment_choices.size(), 1u);
  EXPECT_EQ(m->segment_choices[0].segments, 7);
  EXPECT_TRUE(m->segment_choices[0].pinned);
  EXPECT_EQ(m->beams.size(), 7u);
}

// What "auto" refuses, each with its pointer.
TEST(AutoSegments, BadInputIsReportedWithItsPointer) {
  const auto problems = [](const Json& scene) {
    Diagnostics diag;
    const auto m = load_scene(scene, {"f.json", ""}, diag);
    EXPECT_FALSE(m);
    return diag.format();
  };
  Scene s = cantilever(2.0, "fine");
  EXPECT_NE(problems(s.j).find("f.json:/beams/0/segments: expected an integer >= 0 or \"auto\""),
            std::string::npos)
      << problems(s.j);
  s = cantilever(2.0, "auto");
  s.j["segmentation"] = {{"frequency_error", 2.0}};
  EXPECT_NE(problems(s.j).find("f.json:/segmentation/frequency_error: must be < 1"),
            std::string::npos)
      << problems(s.j);
  s.j["segmentation"] = {{"max_frequency_hz", -5.0}};
  EXPECT_NE(problems(s.j).find("f.json:/segmentation/max_frequency_hz"), std::string::npos)
      << problems(s.j);
  s = cantilever(2.0, "auto");
  s.j["materials"]["steel"].erase("density");
  EXPECT_NE(problems(s.j).find("f.json:/beams/0/segments: a segmented beam needs a material with "
                               "a density > 0"),
            std::string::npos)
      << problems(s.j);
}

// A target beyond the ladder is a warning (at the beam's segments), and the largest count is used.
TEST(AutoSegments, AnUnreachableTargetIsAWarning) {
  Scene s = cantilever(2.0, "auto");
  s.j["segmentation"] = {{"frequency_error", 1e-9}};
  Diagnostics diag;
  const auto m = load_scene(s.j, {"f.json", ""}, diag);
  ASSERT_TRUE(m) << diag.format();
  EXPECT_EQ(m->segment_choices[0].segments, kMaxAutoSegments);
  EXPECT_FALSE(m->segment_choices[0].reached);
  ASSERT_EQ(diag.warning_lines().size(), 1u);
  EXPECT_NE(diag.warning_lines()[0].find("f.json:/beams/0/segments: beam \"arm\": 128 segments"),
            std::string::npos)
      << diag.warning_lines()[0];
}

}  // namespace
}  // namespace beamrail
