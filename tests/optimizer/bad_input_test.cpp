// Bad input through the real command line: every broken study exits with status 2 and lists each
// problem as one line "file:/json/pointer: message" on stderr (docs/study_files.md "Command line"),
// without a crash, a hang or an uncaught exception. Each test starts from a valid study and breaks
// one thing.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#ifndef BEAMRAIL_EXECUTABLE
#error "BEAMRAIL_EXECUTABLE must name the beamrail binary"
#endif

namespace beamrail {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using Pointer = Json::json_pointer;

// A valid study with every kind of scene part: two free bodies, a beam, a rail, a force with a
// ramp and a torque with a table, a transient analysis with an integrator, two responses.
constexpr const char* kBaseStudy = R"({
  "name": "base",
  "description": "valid base study for the bad-input tests",
  "scene": {
    "gravity": [0, 0, -9.81],
    "materials": {"steel": {"E": 2.1e11, "G": 8.1e10, "density": 7850}},
    "sections": {
      "sq10": {"shape": "rectangle", "width": 0.01, "height": 0.01},
      "given": {"shape": "custom", "S": 1e-4, "Ix": 1.4e-9, "Iy": 8.3e-10, "Iz": 8.3e-10}
    },
    "bodies": [
      {"name": "tip", "mass": 1.0, "inertia": [0.001, 0.001, 0.001], "position": [1, 0, 0]},
      {"name": "carriage", "mass": 0.5, "inertia": [0.001, 0.001, 0.001], "position": [0, 1, 0]}
    ],
    "beams": [
      {"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0], "point2": [1, 0, 0],
       "point3": [0, 1, 0], "material": "steel", "section": "sq10", "formulation": "energy"}
    ],
    "rails": [
      {"name": "guide", "type": "prismatic", "body1": "ground", "body2": "carriage",
       "point1": [0, 0, 0], "point2": [0, 1, 0], "point3": [1, 0, 0],
       "material": "steel", "section": "given", "min_length": 0.001}
    ],
    "loads": [
      {"type": "force", "body": "tip", "point": [1, 0, 0], "value": [0, -1, 0],
       "time": {"type": "ramp", "from": 0.0, "to": 0.1}},
      {"type": "torque", "body": "tip", "value": [0, 0, 0.1],
       "time": {"type": "table", "t": [0, 0.1, 0.2], "v": [0, 1, 1]}}
    ]
  },
  "analyses": [
    {"type": "transient", "t_end": 0.01, "output_step": 0.001,
     "integrator": {"method": "bdf", "rtol": 1e-6, "atol": 1e-9}}
  ],
  "responses": {
    "tip_peak": {"quantity": "peak_displacement", "body": "tip", "direction": [0, 1, 0]},
    "mass": {"quantity": "mass"}
  }
})";

struct Result {
  bool exited = false;  // false: killed by a signal or by the time limit
  int status = -1;      // exit status when exited
  std::string how;      // how it ended, for failure messages
  std::string out, err;
};

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

class BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "beamrail_bad_input_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    fs::permissions(dir_, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(dir_, ec);
  }

  static Json base() { return Json::parse(kBaseStudy); }

  void write(const std::string& name, const std::string& text) {
    fs::create_directories((dir_ / name).parent_path());
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }

  // Runs the binary in the temporary directory (so that messages name files as given here), with
  // a time limit: a hang fails like a crash.
  Result run(const std::vector<std::string>& args) {
    const std::string exe = BEAMRAIL_EXECUTABLE;
    const std::string dir = dir_.string();
    const std::string out_path = (dir_ / ".stdout").string(),
                      err_path = (dir_ / ".stderr").string();
    std::vector<std::string> storage{exe};
    storage.insert(storage.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : storage) argv.push_back(a.data());
    argv.push_back(nullptr);

    const pid_t pid = fork();
    if (pid < 0) {
      ADD_FAILURE() << "fork failed";
      return {};
    }
    if (pid == 0) {  // only async-signal-safe calls until exec
      const int out = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int err = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (out < 0 || err < 0 || chdir(dir.c_str()) != 0) _exit(127);
      dup2(out, 1);
      dup2(err, 2);
      execv(exe.c_str(), argv.data());
      _exit(127);
    }
    Result r;
    int status = 0;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    for (;;) {
      const pid_t w = waitpid(pid, &status, WNOHANG);
      if (w == pid) break;
      if (w < 0 || std::chrono::steady_clock::now() > deadline) {
        kill(pid, SIGKILL);
        waitpid(pid, &status, 0);
        r.how = "killed after 60 s (hang)";
        r.out = read_text(out_path), r.err = read_text(err_path);
        return r;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    r.exited = WIFEXITED(status);
    if (r.exited) {
      r.status = WEXITSTATUS(status);
      r.how = "exit status " + std::to_string(r.status);
    } else {
      r.how = WIFSIGNALED(status) ? "terminated by signal " + std::to_string(WTERMSIG(status))
                                  : "ended abnormally";
    }
    r.out = read_text(out_path);
    r.err = read_text(err_path);
    return r;
  }

  Result check(const Json& study, const std::string& name = "bad.json") {
    write(name, study.dump(2));
    return run({"check", name});
  }
  Result check_text(const std::string& text, const std::string& name = "bad.json") {
    write(name, text);
    return run({"check", name});
  }

  // The base study with one value replaced (or added) at a JSON pointer.
  static Json with(const std::string& pointer, const Json& value) {
    Json study = base();
    study[Pointer(pointer)] = value;
    return study;
  }
  // The base study without the member at a JSON pointer.
  static Json without(const std::string& pointer) {
    Json study = base();
    const Pointer p(pointer);
    Json& parent = study[p.parent_pointer()];
    if (parent.is_array())
      parent.erase(std::stoul(p.back()));
    else
      parent.erase(p.back());
    return study;
  }

  fs::path dir_;
};

// Status 2 and a line of stderr that starts with `prefix` and contains `phrase`.
::testing::AssertionResult HasError(const Result& r, const std::string& prefix,
                                    const std::string& phrase) {
  if (!r.exited || r.status != 2)
    return ::testing::AssertionFailure() << "expected exit status 2, got " << r.how << "; stderr:\n"
                                         << r.err;
  for (const std::string& line : lines_of(r.err))
    if (line.rfind(prefix, 0) == 0 && line.find(phrase) != std::string::npos)
      return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "no line starting with \"" << prefix
                                       << "\" and containing \"" << phrase << "\" in stderr:\n"
                                       << r.err;
}

// As HasError, and that is the only problem reported (no cascade of follow-up messages).
::testing::AssertionResult HasOnlyError(const Result& r, const std::string& prefix,
                                        const std::string& phrase) {
  auto result = HasError(r, prefix, phrase);
  if (!result) return result;
  const size_t n = lines_of(r.err).size();
  if (n != 1)
    return ::testing::AssertionFailure() << "expected exactly one problem, got " << n << ":\n"
                                         << r.err;
  return ::testing::AssertionSuccess();
}

size_t line_count(const Result& r) { return lines_of(r.err).size(); }

// --- The base study is valid ------------------------------------------------------------------

TEST_F(BadInput, CheckOnTheValidBaseStudyExitsZero) {
  const Result r = check(base(), "base.json");
  ASSERT_TRUE(r.exited) << r.how;
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_NE(r.out.find("base.json: ok (2 bodies, 1 beams, 1 rails"), std::string::npos) << r.out;
}

// --- Unknown keys -----------------------------------------------------------------------------

TEST_F(BadInput, UnknownKeyAtEveryLevelWithDidYouMean) {
  const struct {
    const char* pointer;
    const char* hint;
  } cases[] = {
      {"/nmae", "name"},
      {"/scene/gravty", "gravity"},
      {"/scene/bodies/0/mas", "mass"},
      {"/scene/beams/0/secton", "section"},
      {"/scene/rails/0/min_lenght", "min_length"},
      {"/scene/loads/0/valeu", "value"},
      {"/scene/loads/0/time/fro", "from"},
      {"/scene/materials/steel/densty", "density"},
      {"/scene/sections/sq10/widht", "width"},
      {"/analyses/0/t_ned", "t_end"},
      {"/analyses/0/integrator/rtl", "rtol"},
      {"/responses/tip_peak/directon", "direction"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.pointer);
    const std::string key = Pointer(c.pointer).back();
    const Result r = check(with(c.pointer, 1));
    EXPECT_TRUE(HasOnlyError(r, std::string("bad.json:") + c.pointer + ":",
                             "unknown key \"" + key + "\" (did you mean \"" + c.hint + "\"?)"));
  }
}

TEST_F(BadInput, UnknownKeyWithoutACloseMatchHasNoHint) {
  const Result r = check(with("/responses/mass/colour", "red"));
  EXPECT_TRUE(HasOnlyError(r, "bad.json:/responses/mass/colour:", "unknown key \"colour\""));
  EXPECT_EQ(r.err.find("did you mean"), std::string::npos) << r.err;
}

// --- Missing and mistyped fields ----------------------------------------------------------------

TEST_F(BadInput, MissingRequiredField) {
  EXPECT_TRUE(HasOnlyError(check(without("/scene/bodies/0/position")),
                           "bad.json:/scene/bodies/0:", "missing required key \"position\""));
  EXPECT_TRUE(HasOnlyError(check(without("/scene/materials/steel/E")),
                           "bad.json:/scene/materials/steel:", "missing required key \"E\""));
  EXPECT_TRUE(HasOnlyError(check(without("/scene/beams/0/material")),
                           "bad.json:/scene/beams/0:", "missing required key \"material\""));
  EXPECT_TRUE(HasOnlyError(check(without("/analyses/0/t_end")),
                           "bad.json:/analyses/0:", "missing required key \"t_end\""));
  EXPECT_TRUE(
      HasOnlyError(check(without("/analyses")), "bad.json: ", "missing required key \"analyses\""));
}

TEST_F(BadInput, StringWhereANumberIsExpected) {
  // One problem only: not also "a free body with an inertia needs a mass".
  EXPECT_TRUE(HasOnlyError(check(with("/scene/bodies/0/mass", "1.0")),
                           "bad.json:/scene/bodies/0/mass:", "expected a number, got a string"));
  EXPECT_TRUE(
      HasOnlyError(check(with("/scene/bodies/0/position/1", "0")),
                   "bad.json:/scene/bodies/0/position/1:", "expected a number, got a string"));
}

TEST_F(BadInput, NumberWhereAnArrayIsExpected) {
  EXPECT_TRUE(HasOnlyError(
      check(with("/scene/bodies/0/position", 1)),
      "bad.json:/scene/bodies/0/position:", "expected an array of numbers, got a number"));
  EXPECT_TRUE(HasOnlyError(check(with("/scene/bodies", 2)),
                           "bad.json:/scene/bodies:", "expected an array, got a number"));
}

TEST_F(BadInput, WrongArrayLength) {
  EXPECT_TRUE(HasOnlyError(check(with("/scene/bodies/0/position", {1, 0})),
                           "bad.json:/scene/bodies/0/position:", "expected 3 numbers, got 2"));
  EXPECT_TRUE(HasOnlyError(check(with("/scene/beams/0/point3", {0, 1, 0, 0})),
                           "bad.json:/scene/beams/0/point3:", "expected 3 numbers, got 4"));
  EXPECT_TRUE(
      HasOnlyError(check(with("/scene/bodies/0/inertia", {1, 1, 1, 0})),
                   "bad.json:/scene/bodies/0/inertia:", "expected 3 principal values or 6"));
}

TEST_F(BadInput, NonFiniteNumberInTheText) {
  std::string text = base().dump(2);
  const std::string mass = "\"mass\": 1.0";
  ASSERT_NE(text.find(mass), std::string::npos);
  text.replace(text.find(mass), mass.size(), "\"mass\": 1e999");
  EXPECT_TRUE(HasOnlyError(check_text(text), "bad.json:/scene/bodies/0/mass:",
                           "number 1e999 is out of range (not a finite double)"));
  // Inside an array, negative, and with the position in the text.
  EXPECT_TRUE(HasOnlyError(check_text(R"({"name": "x", "scene": {"gravity": [0,
      -1e400, 0]}})"),
                           "bad.json:/scene/gravity/1:", "-1e400 is out of range"));
  EXPECT_TRUE(HasOnlyError(check_text(R"({"name": "x", "scene": {"gravity": [0,
      -1e400, 0]}})"),
                           "bad.json:", "at line 2, column 7"));
}

// --- Physics: materials, sections, bodies -------------------------------------------------------

TEST_F(BadInput, NonPositiveModuli) {
  // One problem each: the beam and the rail that use "steel" do not add "unknown material".
  EXPECT_TRUE(HasOnlyError(check(with("/scene/materials/steel/E", 0)),
                           "bad.json:/scene/materials/steel/E:", "must be > 0, got 0"));
  EXPECT_TRUE(HasOnlyError(check(with("/scene/materials/steel/G", -8.1e10)),
                           "bad.json:/scene/materials/steel/G:", "must be > 0, got -8.1e+10"));
  EXPECT_TRUE(HasOnlyError(check(with("/scene/materials/steel/density", -1)),
                           "bad.json:/scene/materials/steel/density:", "must be >= 0, got -1"));
}

TEST_F(BadInput, NonPositiveSectionDimensions) {
  EXPECT_TRUE(HasOnlyError(check(with("/scene/sections/sq10/width", 0)),
                           "bad.json:/scene/sections/sq10/width:", "must be > 0"));
  EXPECT_TRUE(HasOnlyError(check(with("/scene/sections/sq10/height", -0.01)),
                           "bad.json:/scene/sections/sq10/height:", "must be > 0"));
  EXPECT_TRUE(
      HasOnlyError(check(with("/scene/sections/sq10", {{"shape", "circle"}, {"diameter", 0}})),
                   "bad.json:/scene/sections/sq10/diameter:", "must be > 0"));
  EXPECT_TRUE(HasOnlyError(
      check(with("/scene/sections/sq10",
                 {{"shape", "tube"}, {"outer_diameter", 0.02}, {"wall", 0.01}})),
      "bad.json:/scene/sections/sq10/wall:", "must be less than half the outer diameter"));
}

TEST_F(BadInput, NonPositiveCustomSectionProperties) {
  Json study = base();
  Json& given = study["scene"]["sections"]["given"];
  given["S"] = 0;
  given["Ix"] = -1e-9;
  given["Iy"] = 0.0;
  given["Iz"] = -8.3e-10;
  const Result r = check(study);
  EXPECT_TRUE(HasError(r, "bad.json:/scene/sections/given/S:", "must be > 0, got 0"));
  EXPECT_TRUE(HasError(r, "bad.json:/scene/sections/given/Ix:", "must be > 0, got -1e-09"));
  EXPECT_TRUE(HasError(r, "bad.json:/scene/sections/given/Iy:", "must be > 0, got 0"));
  EXPECT_TRUE(HasError(r, "bad.json:/scene/sections/given/Iz:", "must be > 0, got -8.3e-10"));
  EXPECT_EQ(line_count(r), 4u) << r.err;  // and no "unknown section" at the rail
}

TEST_F(BadInput, NonPositiveMass) {
  EXPECT_TRUE(HasOnlyError(check(with("/scene/bodies/0/mass", 0)),
                           "bad.json:/scene/bodies/0/mass:", "must be > 0, got 0"));
  EXPECT_TRUE(HasOnlyError(check(with("/scene/bodies/1/mass", -2)),
                           "bad.json:/scene/bodies/1/mass:", "must be > 0, got -2"));
}

TEST_F(BadInput, NonPositivePrincipalInertia) {
  EXPECT_TRUE(HasOnlyError(check(with("/scene/bodies/0/inertia", {0.001, 0, 0.001})),
                           "bad.json:/scene/bodies/0/inertia:", "principal inertias must be > 0"));
  EXPECT_TRUE(HasOnlyError(check(with("/scene/bodies/0/inertia", {0.001, 0.001, -0.001})),
                           "bad.json:/scene/bodies/0/inertia:", "principal inertias must be > 0"));
}

TEST_F(BadInput, InertiaViolatingTheTriangleInequality) {
  EXPECT_TRUE(HasOnlyError(
      check(with("/scene/bodies/0/inertia", {1, 1, 3})),
      "bad.json:/scene/bodies/0/inertia:", "violate the triangle inequality (1 + 1 < 3)"));
  // The same for a tensor, after diagonalisation.
  EXPECT_TRUE(HasOnlyError(check(with("/scene/bodies/0/inertia", {1, 1, 3, 0, 0, 0})),
                           "bad.json:/scene/bodies/0/inertia:", "triangle inequality"));
}

TEST_F(BadInput, InertiaTensorNotPositiveDefinite) {
  EXPECT_TRUE(HasOnlyError(
      check(with("/scene/bodies/0/inertia", {1, 1, 1, 2, 0, 0})),
      "bad.json:/scene/bodies/0/inertia:", "inertia tensor must be positive definite"));
}

// --- Geometry and references --------------------------------------------------------------------

TEST_F(BadInput, CoincidentEndPoints) {
  EXPECT_TRUE(HasOnlyError(check(with("/scene/beams/0/point2", {0, 0, 0})),
                           "bad.json:/scene/beams/0/point2:", "point1 and point2 coincide"));
  EXPECT_TRUE(HasOnlyError(check(with("/scene/rails/0/point1", {0, 1, 0})),
                           "bad.json:/scene/rails/0/point2:", "point1 and point2 coincide"));
}

TEST_F(BadInput, Point3OnTheAxis) {
  EXPECT_TRUE(HasOnlyError(check(with("/scene/beams/0/point3", {2, 0, 0})),
                           "bad.json:/scene/beams/0/point3:", "point3 lies on the axis"));
  EXPECT_TRUE(HasOnlyError(check(with("/scene/rails/0/point3", {0, -3, 0})),
                           "bad.json:/scene/rails/0/point3:", "point3 lies on the axis"));
}

TEST_F(BadInput, UnknownBodyName) {
  EXPECT_TRUE(HasOnlyError(check(with("/scene/beams/0/body2", "tpi")),
                           "bad.json:/scene/beams/0/body2:", "unknown body \"tpi\""));
  EXPECT_TRUE(HasOnlyError(check(with("/scene/rails/0/body1", "Ground")),
                           "bad.json:/scene/rails/0/body1:", "unknown body \"Ground\""));
  EXPECT_TRUE(HasOnlyError(check(with("/scene/loads/1/body", "top")),
                           "bad.json:/scene/loads/1/body:", "unknown body \"top\""));
  EXPECT_TRUE(HasOnlyError(check(with("/responses/tip_peak/body", "tp")),
                           "bad.json:/responses/tip_peak/body:", "unknown body \"tp\""));
}

TEST_F(BadInput, UnknownMaterialName) {
  EXPECT_TRUE(HasOnlyError(check(with("/scene/beams/0/material", "stel")),
                           "bad.json:/scene/beams/0/material:", "unknown material \"stel\""));
}

TEST_F(BadInput, UnknownSectionName) {
  EXPECT_TRUE(HasOnlyError(check(with("/scene/rails/0/section", "tube4O")),
                           "bad.json:/scene/rails/0/section:", "unknown section \"tube4O\""));
}

TEST_F(BadInput, DuplicateBodyName) {
  Json study = base();
  Json extra = study["scene"]["bodies"][1];
  extra["name"] = "tip";
  study["scene"]["bodies"].push_back(extra);
  EXPECT_TRUE(
      HasOnlyError(check(study), "bad.json:/scene/bodies/2/name:", "duplicate body name \"tip\""));
}

TEST_F(BadInput, DuplicateElementNameAcrossBeamsAndRails) {
  EXPECT_TRUE(HasOnlyError(check(with("/scene/rails/0/name", "arm")),
                           "bad.json:/scene/rails/0/name:", "duplicate element name \"arm\""));
}

TEST_F(BadInput, GroundAsABodyName) {
  Json study = base();
  Json extra = study["scene"]["bodies"][1];
  extra["name"] = "ground";
  study["scene"]["bodies"].push_back(extra);
  EXPECT_TRUE(HasOnlyError(
      check(study), "bad.json:/scene/bodies/2/name:", "\"ground\" is the implicit fixed body"));
}

TEST_F(BadInput, NoFreeBodyWhenAllAreFixed) {
  Json study = base();
  for (Json& b : study["scene"]["bodies"]) b["fixed"] = true;
  study["scene"].erase("loads");
  EXPECT_TRUE(HasOnlyError(check(study), "bad.json:/scene/bodies:", "the scene has no free body"));
}

TEST_F(BadInput, NoFreeBodyWhenThereAreNoBodies) {
  Json study = base();
  study["scene"]["bodies"] = Json::array();
  for (const char* key : {"beams", "rails", "loads"}) study["scene"].erase(key);
  study["responses"].erase("tip_peak");
  EXPECT_TRUE(HasOnlyError(check(study), "bad.json:/scene/bodies:", "the scene has no free body"));
}

TEST_F(BadInput, ElementJoiningABodyToItself) {
  EXPECT_TRUE(
      HasOnlyError(check(with("/scene/beams/0/body1", "tip")),
                   "bad.json:/scene/beams/0/body2:", "an element must join two different bodies"));
}

// --- Enumerations -------------------------------------------------------------------------------

// Each wrong value is reported once, with the choices; the members that belong to the right
// variant are not reported as unknown on top of it.
TEST_F(BadInput, WrongEnumValues) {
  const struct {
    const char* pointer;
    const char* value;
    const char* choices;
  } cases[] = {
      {"/scene/beams/0/formulation", "exact", "(expected one of \"energy\", \"paper\")"},
      {"/scene/rails/0/type", "revolute", "(expected one of \"prismatic\", \"cylindrical\")"},
      {"/analyses/0/integrator/method", "rk4", "\"bdf\""},
      {"/analyses/0/integrator/about", "sideways", "(expected one of \"static\", \"initial\")"},
      {"/scene/loads/0/type", "moment", "(expected one of \"force\", \"torque\")"},
      {"/scene/loads/0/time/type", "sine", "\"ramp\", \"harmonic\", \"table\""},
      {"/scene/sections/sq10/shape", "square", "\"rectangle\", \"circle\""},
      {"/analyses/0/type", "transiant", "\"transient\""},
      {"/responses/tip_peak/quantity", "peak", "\"peak_displacement\""},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.pointer);
    const Result r = check(with(c.pointer, c.value));
    EXPECT_TRUE(HasOnlyError(r, std::string("bad.json:") + c.pointer + ":",
                             std::string("unknown value \"") + c.value + "\""));
    EXPECT_NE(r.err.find(c.choices), std::string::npos) << r.err;
  }
}

TEST_F(BadInput, IntegratorOptionsOfAnotherMethod) {
  // Options that belong to one method family, given to another (the base study uses bdf).
  const struct {
    const char* key;
    Json value;
    const char* message;
  } cases[] = {
      {"table", "VERNER_8_5_6", "a Butcher table applies to the \"dirk\" and \"erk\" methods"},
      {"about", "initial", "applies to the \"modal\" and \"auto\" methods"},
      {"max_frequency_hz", 100.0, "applies to the \"modal\" and \"auto\" methods"},
      {"stability_limit_detection", true, "applies to the \"bdf\" method"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.key);
    Json study = base();
    study["analyses"][0]["integrator"]["method"] =
        c.key == std::string("stability_limit_detection") ? "dirk" : "bdf";
    study["analyses"][0]["integrator"][c.key] = c.value;
    const Result r = check(study);
    EXPECT_TRUE(
        HasOnlyError(r, std::string("bad.json:/analyses/0/integrator/") + c.key + ":", c.message));
  }
}

// A transient's band: a frequency > 0 or "output", and only for the methods that have one.
TEST_F(BadInput, TransientBand) {
  const std::string at = "bad.json:/analyses/0/max_frequency_hz:";
  EXPECT_TRUE(HasOnlyError(check(with("/analyses/0/max_frequency_hz", "fast")), at,
                           "expected a frequency [Hz] > 0 or \"output\""));
  EXPECT_TRUE(HasOnlyError(check(with("/analyses/0/max_frequency_hz", -5.0)), at, "> 0"));
  Json study = with("/analyses/0/max_frequency_hz", "output");
  study["analyses"][0]["integrator"]["method"] = "dirk";
  EXPECT_TRUE(HasOnlyError(check(study), at, "applies to the \"modal\" and \"auto\" methods"));
  study["analyses"][0]["integrator"]["method"] = "auto";
  const Result ok = check(study);
  EXPECT_TRUE(ok.exited && ok.status == 0) << ok.how << ": " << ok.err;
}

// --- Loads and time functions -------------------------------------------------------------------

TEST_F(BadInput, LoadOnAFixedBody) {
  Json study = with("/scene/bodies/1/fixed", true);
  study["scene"]["loads"][0]["body"] = "carriage";
  EXPECT_TRUE(
      HasOnlyError(check(study), "bad.json:/scene/loads/0/body:", "body \"carriage\" is fixed"));
  EXPECT_TRUE(HasOnlyError(check(with("/scene/loads/1/body", "ground")),
                           "bad.json:/scene/loads/1/body:", "body \"ground\" is fixed"));
}

// "follows" is true or false; anything else is one error at its pointer, and a misspelling is an
// unknown key with the hint. A valid follower load passes the check.
TEST_F(BadInput, FollowerLoadFlag) {
  const struct {
    Json value;
    const char* got;
  } cases[] = {{"yes", "got a string"}, {1, "got a number"}, {Json::array({true}), "got an array"}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.value.dump());
    EXPECT_TRUE(HasOnlyError(
        check(with("/scene/loads/1/follows", c.value)),
        "bad.json:/scene/loads/1/follows:", std::string("expected true or false, ") + c.got));
  }
  EXPECT_TRUE(HasOnlyError(
      check(with("/scene/loads/0/follow", true)),
      "bad.json:/scene/loads/0/follow:", "unknown key \"follow\" (did you mean \"follows\"?)"));
  Json study = with("/scene/loads/0/follows", true);
  study["scene"]["loads"][1]["follows"] = false;
  const Result ok = check(study);
  EXPECT_TRUE(ok.exited && ok.status == 0) << ok.how << ": " << ok.err;
}

// Joints: an unknown body, a zero axis, a duplicate name, an axis on a joint without one and a
// point far from both bodies are each one error at their pointer; a valid joint passes.
TEST_F(BadInput, Joints) {
  const Json hinge = {{"name", "hinge"},     {"type", "revolute"}, {"body1", "tip"},
                      {"body2", "carriage"}, {"point", {1, 0, 0}}, {"axis", {0, 0, 1}}};
  const Result ok = check(with("/scene/joints", Json::array({hinge})));
  EXPECT_TRUE(ok.exited && ok.status == 0) << ok.how << ": " << ok.err;
  EXPECT_NE(ok.out.find("1 rails, 1 joints,"), std::string::npos) << ok.out;
  const auto changed = [&](const std::string& key, const Json& value) {
    Json j = hinge;
    j[key] = value;
    return with("/scene/joints", Json::array({j}));
  };
  EXPECT_TRUE(HasOnlyError(check(changed("body2", "nobody")),
                           "bad.json:/scene/joints/0/body2:", "unknown body \"nobody\""));
  EXPECT_TRUE(HasOnlyError(check(changed("axis", Json::array({0, 0, 0}))),
                           "bad.json:/scene/joints/0/axis:", "must be a non-zero direction"));
  EXPECT_TRUE(HasOnlyError(check(changed("name", "arm")),
                           "bad.json:/scene/joints/0/name:", "duplicate element name \"arm\""));
  Json twice = with("/scene/joints", Json::array({hinge, hinge}));
  EXPECT_TRUE(HasOnlyError(check(twice),
                           "bad.json:/scene/joints/1/name:", "duplicate element name \"hinge\""));
  Json spherical = hinge;
  spherical["type"] = "spherical";
  EXPECT_TRUE(HasOnlyError(check(with("/scene/joints", Json::array({spherical}))),
                           "bad.json:/scene/joints/0/axis:", "only a revolute joint has an axis"));
  const Result far = check(changed("point", Json::array({50, 0, 0})));
  EXPECT_TRUE(HasOnlyError(far, "bad.json:/scene/joints/0/point:", "beyond both bodies' extent"));
  EXPECT_EQ(far.status, 2);
}

TEST_F(BadInput, TableTimesNotIncreasing) {
  EXPECT_TRUE(
      HasOnlyError(check(with("/scene/loads/1/time/t", {0, 0.2, 0.1})),
                   "bad.json:/scene/loads/1/time/t/2:", "times must be strictly increasing"));
  EXPECT_TRUE(
      HasOnlyError(check(with("/scene/loads/1/time/t", {0, 0, 0.1})),
                   "bad.json:/scene/loads/1/time/t/1:", "times must be strictly increasing"));
  EXPECT_TRUE(HasOnlyError(check(with("/scene/loads/1/time/v", {0, 1})),
                           "bad.json:/scene/loads/1/time/v:", "as many values as \"t\" (3)"));
}

TEST_F(BadInput, RampEndNotAfterItsStart) {
  EXPECT_TRUE(HasOnlyError(check(with("/scene/loads/0/time/to", 0.0)),
                           "bad.json:/scene/loads/0/time/to:", "must be greater than \"from\""));
  EXPECT_TRUE(HasOnlyError(check(with("/scene/loads/0/time/to", -1.0)),
                           "bad.json:/scene/loads/0/time/to:", "must be greater than \"from\""));
}

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
}  // namespace beamrail
