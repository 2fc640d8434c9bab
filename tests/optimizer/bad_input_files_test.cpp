// Bad input through the real command line (continued from bad_input_test.cpp): broken JSON text
// and files, scene files, many problems at once, and the command line itself. Each exits with
// status 2 and lists its problems as "file:/json/pointer: message" lines, without a crash or hang.
#include <gtest/gtest.h>

#include "tests/support/bad_input_fixture.hpp"

namespace beamrail::bad_input {
namespace {

// --- JSON text and files ------------------------------------------------------------------------

TEST_F(BadInput, InvalidJsonSyntaxGivesLineAndColumn) {
  // The stray comma is the 13th character of line 3.
  EXPECT_TRUE(HasOnlyError(check_text("{\n  \"name\": \"x\",\n  \"scene\": {,\n}\n"),
                           "bad.json: ", "invalid JSON at line 3, column 13"));
  // A missing closing brace is reported at the end of the text.
  EXPECT_TRUE(HasOnlyError(check_text("{\"name\": \"x\"\n"),
                           "bad.json: ", "invalid JSON at line 2, column 1"));
  EXPECT_TRUE(HasOnlyError(check_text(""), "bad.json: ", "invalid JSON at line 1, column 1"));
}

TEST_F(BadInput, DuplicateKeysAreErrors) {
  std::string text = base().dump(2);
  const std::string mass = "\"mass\": 1.0";
  text.replace(text.find(mass), mass.size(), "\"mass\": 1.0, \"mass\": 2.0");
  EXPECT_TRUE(
      HasOnlyError(check_text(text), "bad.json:/scene/bodies/0/mass:", "duplicate key \"mass\""));

  text = base().dump(2);
  const std::string materials = "\"materials\": {";
  text.replace(text.find(materials), materials.size(),
               "\"materials\": {\"steel\": {\"E\": 7e10, \"G\": 2.6e10}, ");
  EXPECT_TRUE(HasOnlyError(check_text(text),
                           "bad.json:/scene/materials/steel:", "duplicate key \"steel\""));

  // Nested in arrays, several at once, and a "~" escaped in the pointer.
  EXPECT_TRUE(HasError(check_text(R"({"a": [1, {"b~c": 1, "b~c": 2}], "x": 1, "x": 2})"),
                       "bad.json:/a/1/b~0c:", "duplicate key \"b~c\""));
  EXPECT_TRUE(HasError(check_text(R"({"a": [1, {"b~c": 1, "b~c": 2}], "x": 1, "x": 2})"),
                       "bad.json:/x:", "duplicate key \"x\""));
}

TEST_F(BadInput, MissingStudyFile) {
  EXPECT_TRUE(HasOnlyError(run({"check", "nosuch.json"}),
                           "nosuch.json: ", "cannot read file: No such file or directory"));
  EXPECT_TRUE(
      HasOnlyError(run({"run", "nosuch.json", "--quiet"}), "nosuch.json: ", "cannot read file"));
  fs::create_directories(dir_ / "folder.json");
  EXPECT_TRUE(HasOnlyError(run({"check", "folder.json"}), "folder.json: ", "it is a directory"));
}

TEST_F(BadInput, UnreadableStudyFile) {
  write("locked.json", base().dump());
  fs::permissions(dir_ / "locked.json", fs::perms::none);
  if (access((dir_ / "locked.json").c_str(), R_OK) == 0)
    GTEST_SKIP() << "running with privileges that read any file";
  EXPECT_TRUE(HasOnlyError(run({"check", "locked.json"}),
                           "locked.json: ", "cannot read file: Permission denied"));
}

TEST_F(BadInput, SceneFileMissing) {
  EXPECT_TRUE(HasOnlyError(check(with("/scene", "parts/nosuch_scene.json")),
                           "bad.json:/scene:", "scene file \"parts/nosuch_scene.json\" not found"));
}

TEST_F(BadInput, SceneFileWithErrorsNamesTheSceneFile) {
  Json scene = base()["scene"];
  scene["bodies"][0]["mass"] = -1;
  scene["beams"][0]["colour"] = "red";
  write("parts/scene.json", scene.dump(2));
  const Result r = check(with("/scene", "parts/scene.json"));
  EXPECT_TRUE(HasError(r, "parts/scene.json:/bodies/0/mass:", "must be > 0, got -1"));
  EXPECT_TRUE(HasError(r, "parts/scene.json:/beams/0/colour:", "unknown key \"colour\""));
  EXPECT_EQ(line_count(r), 2u) << r.err;

  write("parts/broken.json", "{\"bodies\": [\n  {\"name\": \"tip\",, }\n]}");
  EXPECT_TRUE(HasOnlyError(check(with("/scene", "parts/broken.json")),
                           "parts/broken.json: ", "invalid JSON at line 2, column 18"));

  write("parts/twice.json", R"({"gravity": [0, 0, 1], "gravity": [0, 0, -9.81]})");
  EXPECT_TRUE(HasError(check(with("/scene", "parts/twice.json")),
                       "parts/twice.json:/gravity:", "duplicate key \"gravity\""));
}

TEST_F(BadInput, AStudyFileInAnotherFolderResolvesItsSceneThere) {
  write("sub/scene.json", base()["scene"].dump());
  Json study = base();
  study["scene"] = "scene.json";
  write("sub/study.json", study.dump());
  const Result ok = run({"check", "sub/study.json"});
  EXPECT_EQ(ok.status, 0) << ok.how << "\n" << ok.err;

  Json scene = base()["scene"];
  scene["sections"]["sq10"]["width"] = "wide";
  write("sub/scene.json", scene.dump());
  EXPECT_TRUE(HasOnlyError(run({"check", "sub/study.json"}), "sub/scene.json:/sections/sq10/width:",
                           "expected a number, got a string"));
}

TEST_F(BadInput, EveryIndependentProblemIsListed) {
  Json study = base();
  study["nmae"] = "typo";
  study["scene"]["materials"]["steel"]["G"] = 0;
  study["scene"]["bodies"][1]["position"] = {0, 1};
  study["scene"]["beams"][0]["section"] = "sq11";
  study["scene"]["loads"][1]["time"]["t"] = {0, 0.3, 0.2};
  study["analyses"][0]["integrator"]["rtol"] = -1;
  study["responses"]["tip_peak"]["direction"] = {0, 0, 0};
  const Result r = check(study);
  EXPECT_TRUE(HasError(r, "bad.json:/nmae:", "unknown key"));
  EXPECT_TRUE(HasError(r, "bad.json:/scene/materials/steel/G:", "must be > 0"));
  EXPECT_TRUE(HasError(r, "bad.json:/scene/bodies/1/position:", "expected 3 numbers"));
  EXPECT_TRUE(HasError(r, "bad.json:/scene/beams/0/section:", "unknown section \"sq11\""));
  EXPECT_TRUE(HasError(r, "bad.json:/scene/loads/1/time/t/2:", "strictly increasing"));
  EXPECT_TRUE(HasError(r, "bad.json:/analyses/0/integrator/rtol:", "must be > 0"));
  // Responses are checked even though the scene failed.
  EXPECT_TRUE(HasError(r, "bad.json:/responses/tip_peak/direction:", "zero vector"));
  EXPECT_EQ(line_count(r), 7u) << r.err;
}

TEST_F(BadInput, InvalidMaterialOrSectionIsReportedOnlyWhereDeclared) {
  // Both the beam and the rail use "steel"; a section with a wrong shape keeps its members quiet.
  Json study = with("/scene/materials/steel", {{"E", -1}, {"G", 8.1e10}});
  EXPECT_TRUE(HasOnlyError(check(study), "bad.json:/scene/materials/steel/E:", "must be > 0"));
  study = with("/scene/materials/steel", "steel");
  EXPECT_TRUE(HasOnlyError(check(study),
                           "bad.json:/scene/materials/steel:", "expected an object, got a string"));
  study = with("/scene/sections/sq10/shape", "hexagon");
  EXPECT_TRUE(HasOnlyError(check(study),
                           "bad.json:/scene/sections/sq10/shape:", "unknown value \"hexagon\""));
  // An invalid transient analysis does not make every peak response complain about it.
  EXPECT_TRUE(HasOnlyError(check(with("/analyses/0/t_end", 0)),
                           "bad.json:/analyses/0/t_end:", "must be > 0"));
}

TEST_F(BadInput, PathologicalTextDoesNotCrash) {
  // Nesting deep enough to overflow a recursive reader's stack.
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  EXPECT_TRUE(HasOnlyError(check_text(deep), "bad.json: ", "nesting deeper than 256 levels"));
  // A control character in a key stays escaped on its one line.
  const Result r = check(with("/x\ny", 1));
  EXPECT_TRUE(HasOnlyError(r, "bad.json:/x\\ny:", "unknown key \"x\\ny\""));
  // A document that is not an object.
  EXPECT_TRUE(HasOnlyError(check_text("[1, 2]"), "bad.json: ", "expected an object, got an array"));
}

TEST_F(BadInput, TooManySegments) {
  EXPECT_TRUE(HasOnlyError(check(with("/scene/beams/0/segments", 1e8)),
                           "bad.json:/scene/beams/0/segments:", "at most 100000 segments"));
}

TEST_F(BadInput, RunRejectsBadInputWithStatusTwo) {
  EXPECT_TRUE(HasOnlyError(
      [&] {
        write("bad.json", with("/scene/bodies/0/mass", 0).dump());
        return run({"run", "bad.json", "-o", "out", "--quiet"});
      }(),
      "bad.json:/scene/bodies/0/mass:", "must be > 0"));
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

// --- Command line -------------------------------------------------------------------------------

TEST_F(BadInput, UsageErrorsExitTwo) {
  write("base.json", base().dump());
  const struct {
    std::vector<std::string> args;
    const char* message;
  } cases[] = {
      {{}, "beamrail: no command given"},
      {{"frobnicate", "base.json"}, "beamrail: unknown command frobnicate"},
      {{"check", "base.json", "--verbose"}, "beamrail: unknown option --verbose"},
      {{"run", "base.json", "-x"}, "beamrail: unknown option -x"},
      {{"check"}, "beamrail: no study file given"},
      {{"run", "--quiet"}, "beamrail: no study file given"},
      {{"run", "base.json", "-j", "0"}, "beamrail: -j needs a positive number of threads"},
      {{"run", "base.json", "-j", "two"}, "beamrail: -j needs a positive number of threads"},
      {{"run", "base.json", "-o"}, "beamrail: -o needs a directory"},
      {{"check", "base.json", "other.json"}, "beamrail: more than one study file given"},
  };
  for (const auto& c : cases) {
    std::string joined;
    for (const std::string& a : c.args) joined += " " + a;
    SCOPED_TRACE("beamrail" + joined);
    const Result r = run(c.args);
    ASSERT_TRUE(r.exited) << r.how;
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(r.err.rfind(c.message, 0), 0u) << r.err;
    EXPECT_NE(r.err.find("usage: beamrail run STUDY.json"), std::string::npos) << r.err;
  }
}

TEST_F(BadInput, HelpAndVersionExitZero) {
  Result r = run({"--help"});
  ASSERT_TRUE(r.exited) << r.how;
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("beamrail check STUDY.json"), std::string::npos) << r.out;
  r = run({"--version"});
  ASSERT_TRUE(r.exited) << r.how;
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.out.rfind("beamrail ", 0), 0u) << r.out;
  EXPECT_GT(r.out.size(), std::string("beamrail \n").size()) << r.out;
}

}  // namespace
}  // namespace beamrail::bad_input
