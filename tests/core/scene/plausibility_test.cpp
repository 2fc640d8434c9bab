// Plausibility warnings: a scene that loads but looks mistyped (a diameter in millimetres, a point
// metres from its body, a density a thousand times too large) is reported with the JSON pointer of
// what looks wrong, and still loads; the example studies raise none.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "optimizer/study/study.hpp"
#include "tests/support/run_process.hpp"
#include "tests/support/scene_builder.hpp"

#ifndef BEAMRAIL_EXECUTABLE
#error "BEAMRAIL_EXECUTABLE must name the beamrail binary"
#endif
#ifndef BEAMRAIL_STUDIES_DIR
#error "BEAMRAIL_STUDIES_DIR must name the studies/ directory"
#endif

namespace beamrail {
namespace {

using testing::Scene;
constexpr double kE = 2.1e11, kG = 8.0769e10;

// A planar truss-like frame of 1 m steel tubes between four corner bodies.
Scene frame() {
  Scene s;
  s.material("steel", kE, kG, 7850);
  s.j["sections"]["tube"] = {{"shape", "tube"}, {"outer_diameter", 0.02}, {"wall", 0.002}};
  s.j["sections"]["brace"] = {{"shape", "tube"}, {"outer_diameter", 0.016}, {"wall", 0.002}};
  s.body("a", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(0, 0, 1));
  s.body("b", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(1, 0, 1));
  s.beam("leg_a", "ground", "a", Vec3(0, 0, 0), Vec3(0, 0, 1), "steel", "tube");
  s.beam("leg_b", "ground", "b", Vec3(1, 0, 0), Vec3(1, 0, 1), "steel", "tube");
  s.beam("top", "a", "b", Vec3(0, 0, 1), Vec3(1, 0, 1), "steel", "tube");
  s.beam("brace", "ground", "b", Vec3(0, 0, 0), Vec3(1, 0, 1), "steel", "brace");
  s.force("a", Vec3(10, 0, 0));
  return s;
}

// The warnings of loading the scene (which must load).
std::vector<Diagnostic> warnings_of(const Scene& s) {
  Diagnostics diag;
  const auto model = load_scene(s.j, {"frame.json", "/scene"}, diag);
  EXPECT_TRUE(model.has_value()) << diag.format();
  return diag.warnings();
}

TEST(Plausibility, AWellFormedSceneRaisesNone) {
  const auto w = warnings_of(frame());
  EXPECT_TRUE(w.empty()) << w.front().pointer << ": " << w.front().message;
}

TEST(Plausibility, ADiameterInMillimetres) {
  Scene s = frame();
  s.j["sections"]["brace"]["outer_diameter"] = 16.0;  // mm typed where metres are meant
  const auto w = warnings_of(s);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].pointer, "/scene/sections/brace");
  EXPECT_NE(w[0].message.find("millimetres"), std::string::npos) << w[0].message;
}

TEST(Plausibility, AnAttachmentPointMetresFromItsBody) {
  Scene s = frame();
  s.j["beams"][2]["point2"] = {1, 8.6, 1};  // y mistyped: 8.6 m from body b
  const auto w = warnings_of(s);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].pointer, "/scene/beams/2/point2");
  EXPECT_NE(w[0].message.find("8.6 m from the centre of body \"b\""), std::string::npos)
      << w[0].message;
}

TEST(Plausibility, ALoadPointMetresFromItsBody) {
  Scene s = frame();
  s.j["loads"][0]["point"] = {0, 0, 11};
  const auto w = warnings_of(s);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].pointer, "/scene/loads/0/point");
}

TEST(Plausibility, AMemberAThousandTimesHeavier) {
  Scene s = frame();
  s.j["materials"]["lead"] = {{"E", kE}, {"G", kG}, {"density", 7.85e6}};  // kg/m^3 typo
  s.j["beams"][3]["material"] = "lead";
  const auto w = warnings_of(s);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].pointer, "/scene/beams/3");
  EXPECT_NE(w[0].message.find("density of material \"lead\""), std::string::npos) << w[0].message;
}

TEST(Plausibility, AMemberAHundredTimesLonger) {
  Scene s = frame();
  // A stay from 149 m below: 150 m among 1 m members.
  s.beam("stay", "ground", "a", Vec3(0, 0, -149), Vec3(0, 0, 1), "steel", "brace");
  s.last_beam()["point3"] = testing::vec(1, 0, -149);
  const auto w = warnings_of(s);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].pointer, "/scene/beams/4/point2");
  EXPECT_NE(w[0].message.find("150 m long, 150 times the median length"), std::string::npos)
      << w[0].message;
}

// The examples are what users copy: none of them should look mistyped.
TEST(Plausibility, TheExampleStudiesRaiseNone) {
  int studies = 0;
  for (const auto& entry : std::filesystem::directory_iterator(BEAMRAIL_STUDIES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    Diagnostics diag;
    const auto study = load_study_file(entry.path().string(), diag);
    ASSERT_TRUE(study.has_value()) << diag.format();
    EXPECT_TRUE(study->input_warnings.empty())
        << entry.path() << ": " << study->input_warnings.front();
    ++studies;
  }
  EXPECT_GE(studies, 10);
}

// Through the command line: `check` and `run` print the warning and succeed (exit status 0), and
// summary.json lists it among its warnings.
TEST(Plausibility, WarningsArePrintedAndSummarizedNeverRefused) {
  namespace fs = std::filesystem;
  std::string pattern = (fs::temp_directory_path() / "beamrail_plausible_XXXXXX").string();
  ASSERT_NE(mkdtemp(pattern.data()), nullptr);
  const fs::path dir = pattern;
  Scene s = frame();
  s.j["sections"]["brace"]["outer_diameter"] = 16.0;
  const Json study = {{"name", "typo"},
                      {"scene", s.j},
                      {"analyses", {{{"type", "static"}}}},
                      {"responses", {{"mass", {{"quantity", "mass"}}}}}};
  std::ofstream(dir / "typo.json") << study.dump(2);
  const std::string line =
      "warning: typo.json:/scene/sections/brace: section \"brace\" (of beam \"brace\") has an area";
  for (const char* command : {"check", "run"}) {
    std::vector<std::string> args{command, "typo.json"};
    if (std::string(command) == "run") args.insert(args.end(), {"-o", "out", "--quiet"});
    const testing::ProcessResult r = testing::run_process(BEAMRAIL_EXECUTABLE, args, dir);
    EXPECT_TRUE(r.exited && r.status == 0) << command << ": " << r.how << "\n" << r.err;
    EXPECT_NE(r.err.find(line), std::string::npos) << command << ": " << r.err;
  }
  const Json summary = Json::parse(testing::read_text(dir / "out/summary.json"));
  EXPECT_EQ(summary["status"], "ok");
  // First, before those of the analyses (the static analysis warns too: the brace's stiffness
  // dwarfs the rest).
  ASSERT_GE(summary["warnings"].size(), 1u) << summary["warnings"];
  EXPECT_EQ(summary["warnings"][0].get<std::string>().rfind(line.substr(9), 0), 0u)
      << summary["warnings"][0];
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace
}  // namespace beamrail
