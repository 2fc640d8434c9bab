// Hostile input through the real command line: files that are not what a study or scene should be
// (a directory, a device, the study itself, a loop of scene files, 100 MB of text, deep nesting,
// invalid UTF-8, NUL bytes, nothing at all). Each must exit with status 2 and one line per problem
// "file:/json/pointer: message", in bounded time, never a crash or a hang. The ordinary mistakes
// (missing files, bad values, syntax errors) are in bad_input_test.cpp.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/run_process.hpp"

#ifndef BEAMRAIL_EXECUTABLE
#error "BEAMRAIL_EXECUTABLE must name the beamrail binary"
#endif

namespace beamrail {
namespace {

namespace fs = std::filesystem;
using testing::ProcessResult;

// The largest study or scene file read (json_reader.hpp): 16 MiB.
constexpr size_t kLimit = size_t{16} << 20;

constexpr const char* kScene = R"({
  "materials": {"steel": {"E": 2.1e11, "G": 8.1e10, "density": 7850}},
  "sections": {"sq10": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
  "bodies": [{"name": "tip", "mass": 1.0, "inertia": [0.001, 0.001, 0.001], "position": [1, 0, 0]}],
  "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
             "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq10"}],
  "loads": [{"type": "force", "body": "tip", "value": [0, -1, 0]}]
})";

// A valid study around a scene (an object or a path) and a description.
std::string study_text(const std::string& scene, const std::string& description = "hostile") {
  return R"({"name": "hostile", "description": ")" + description + R"(", "scene": )" + scene +
         R"(, "analyses": [{"type": "static"}],
            "responses": {"dy": {"quantity": "displacement", "body": "tip",
                                 "direction": [0, 1, 0]}}})";
}

std::string quoted(const std::string& path) { return "\"" + path + "\""; }

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// Exit status 2 and exactly one line on stderr: `where` followed by a message containing `what`.
::testing::AssertionResult OnlyError(const ProcessResult& r, const std::string& where,
                                     const std::string& what) {
  if (!r.exited || r.status != 2)
    return ::testing::AssertionFailure() << "expected exit status 2, got " << r.how << "\n"
                                         << r.err;
  const auto lines = lines_of(r.err);
  if (lines.size() != 1)
    return ::testing::AssertionFailure() << "expected one line, got " << lines.size() << ":\n"
                                         << r.err;
  const std::string& line = lines[0];
  if (line.rfind(where, 0) != 0 || line.find(what, where.size()) == std::string::npos)
    return ::testing::AssertionFailure() << "expected \"" << where << " ... " << what << "\", got\n"
                                         << line;
  if (!r.out.empty()) return ::testing::AssertionFailure() << "unexpected stdout: " << r.out;
  return ::testing::AssertionSuccess();
}

class HostileInput : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "beamrail_hostile_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  void write(const std::string& name, const std::string& text) {
    fs::create_directories((dir_ / name).parent_path());
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }

  // Runs the binary in the temporary directory, so that messages name files as given here; a run
  // longer than `limit` is killed and fails.
  ProcessResult run(const std::vector<std::string>& args,
                    std::chrono::milliseconds limit = std::chrono::seconds(30)) {
    return testing::run_process(BEAMRAIL_EXECUTABLE, args, dir_, limit);
  }
  ProcessResult check(const std::string& study_text) {
    write("bad.json", study_text);
    return run({"check", "bad.json"});
  }

  fs::path dir_;
};

TEST_F(HostileInput, TheBaseStudyAndItsSceneFileAreValid) {
  write("parts/scene.json", kScene);
  for (const std::string& scene : {std::string(kScene), quoted("parts/scene.json")}) {
    const ProcessResult r = check(study_text(scene));
    EXPECT_TRUE(r.exited && r.status == 0) << r.how << "\n" << r.err;
    EXPECT_EQ(r.out,
              "bad.json: ok (1 bodies, 1 beams, 0 rails, 13 states, 1 analyses, "
              "1 responses)\n");
  }
}

TEST_F(HostileInput, ScenePathToADirectory) {
  fs::create_directories(dir_ / "parts");
  EXPECT_TRUE(OnlyError(check(study_text(quoted("parts"))),
                        "bad.json:/scene: ", "scene file \"parts\" is a directory"));
  EXPECT_TRUE(OnlyError(check(study_text(quoted("."))),
                        "bad.json:/scene: ", "scene file \".\" is a directory"));
}

TEST_F(HostileInput, ScenePathToADeviceOrAPipe) {
  // A device may never end and a pipe blocks until something writes to it: neither is opened.
  EXPECT_TRUE(OnlyError(check(study_text(quoted("/dev/zero"))),
                        "bad.json:/scene: ", "scene file \"/dev/zero\" is not a regular file"));
  EXPECT_TRUE(OnlyError(check(study_text(quoted("/dev/null"))),
                        "bad.json:/scene: ", "scene file \"/dev/null\" is not a regular file"));
  ASSERT_EQ(mkfifo((dir_ / "pipe.json").c_str(), 0600), 0);
  EXPECT_TRUE(OnlyError(check(study_text(quoted("pipe.json"))),
                        "bad.json:/scene: ", "scene file \"pipe.json\" is not a regular file"));
}

TEST_F(HostileInput, StudyFileFromADevice) {
  // The study itself may come through a pipe (`beamrail check <(...)`), so it is read, but only
  // up to the size limit: an endless device ends in bounded time and memory.
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(OnlyError(run({"check", "/dev/zero"}), "/dev/zero: ",
                        "file too large: more than 16777216 bytes (the limit for a study or scene "
                        "file is 16 MiB)"));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
  EXPECT_TRUE(
      OnlyError(run({"check", "/dev/null"}), "/dev/null: ",
                "invalid JSON at line 1, column 1: the file is empty (expected a JSON object)"));
}

TEST_F(HostileInput, ScenePathThroughALoopOfLinks) {
  fs::create_symlink("loop.json", dir_ / "loop.json");
  EXPECT_TRUE(OnlyError(check(study_text(quoted("loop.json"))), "bad.json:/scene: ",
                        "scene file \"loop.json\" cannot be opened: Too many levels of symbolic "
                        "links"));
  // A path through a file.
  write("parts/scene.json", kScene);
  EXPECT_TRUE(
      OnlyError(check(study_text(quoted("parts/scene.json/scene.json"))), "bad.json:/scene: ",
                "scene file \"parts/scene.json/scene.json\" cannot be opened: Not a directory"));
}

TEST_F(HostileInput, SceneFileWhoseReadingFails) {
  // A regular file whose reading fails for any user: this process's memory from address 0.
  if (!fs::exists("/proc/self/mem")) GTEST_SKIP() << "no /proc/self/mem";
  EXPECT_TRUE(OnlyError(check(study_text(quoted("/proc/self/mem"))),
                        "/proc/self/mem: ", "cannot read file: read error"));
  EXPECT_TRUE(OnlyError(run({"check", "/proc/self/mem"}),
                        "/proc/self/mem: ", "cannot read file: read error"));
}

TEST_F(HostileInput, UnreadableSceneFile) {
  write("parts/locked.json", kScene);
  fs::permissions(dir_ / "parts/locked.json", fs::perms::none);
  if (access((dir_ / "parts/locked.json").c_str(), R_OK) == 0)
    GTEST_SKIP() << "running with privileges that read any file";
  EXPECT_TRUE(OnlyError(check(study_text(quoted("parts/locked.json"))),
                        "parts/locked.json: ", "cannot read file: Permission denied"));
}

TEST_F(HostileInput, ScenePathWithANulCharacter) {
  // The system would open "parts/scene.json", a file the user did not name.
  write("parts/scene.json", kScene);
  EXPECT_TRUE(OnlyError(check(study_text(quoted("parts/scene.json\\u0000.txt"))),
                        "bad.json:/scene: ", "the scene file path contains a NUL character"));
}

TEST_F(HostileInput, SceneThatIsTheStudyItself) {
  for (const char* path : {"bad.json", "./bad.json", "parts/../bad.json"}) {
    fs::create_directories(dir_ / "parts");
    EXPECT_TRUE(OnlyError(check(study_text(quoted(path))), "bad.json:/scene: ",
                          "scene file \"bad.json\" is this study file: the scene file must hold "
                          "the scene object"))
        << path;
  }
  // Through a link as well.
  write("real.json", study_text(quoted("link.json")));
  fs::create_symlink("real.json", dir_ / "link.json");
  EXPECT_TRUE(OnlyError(run({"check", "real.json"}),
                        "real.json:/scene: ", "scene file \"link.json\" is this study file"));
}

TEST_F(HostileInput, SceneFilesThatNameSceneFiles) {
  const std::string message =
      "expected the scene object, got a string (a scene file cannot name another scene file)";
  // A scene file naming itself.
  write("parts/self.json", quoted("self.json"));
  EXPECT_TRUE(
      OnlyError(check(study_text(quoted("parts/self.json"))), "parts/self.json: ", message));
  // A loop of two.
  write("parts/a.json", quoted("b.json"));
  write("parts/b.json", quoted("a.json"));
  EXPECT_TRUE(OnlyError(check(study_text(quoted("parts/a.json"))), "parts/a.json: ", message));
  // A scene file naming the study that names it.
  write("parts/back.json", quoted("../bad.json"));
  EXPECT_TRUE(
      OnlyError(check(study_text(quoted("parts/back.json"))), "parts/back.json: ", message));
}

TEST_F(HostileInput, HundredMegabyteFiles) {
  // A valid study padded to 100 MiB with its description: refused by size before it is read.
  const size_t size = size_t{100} << 20;
  const std::string head = study_text(kScene, "");
  std::string text = study_text(kScene, std::string(size - head.size(), 'x'));
  ASSERT_EQ(text.size(), size);
  write("bad.json", text);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(OnlyError(run({"check", "bad.json"}), "bad.json: ",
                        "file too large: 104857600 bytes (the limit for a study or scene file is "
                        "16 MiB)"));
  EXPECT_TRUE(OnlyError(run({"run", "bad.json", "-o", "out", "--quiet"}),
                        "bad.json: ", "file too large: 104857600 bytes"));
  EXPECT_FALSE(fs::exists(dir_ / "out"));

  // The same as a scene file (100 MiB of spaces before the scene).
  text.assign(size - std::string(kScene).size(), ' ');
  text += kScene;
  write("parts/scene.json", text);
  text.clear();
  text.shrink_to_fit();
  EXPECT_TRUE(OnlyError(check(study_text(quoted("parts/scene.json"))),
                        "parts/scene.json: ", "file too large: 104857600 bytes"));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(20));
}

TEST_F(HostileInput, SizeLimitIsExact) {
  const std::string head = study_text(kScene, "");
  write("bad.json", study_text(kScene, std::string(kLimit - head.size(), 'x')));
  ASSERT_EQ(fs::file_size(dir_ / "bad.json"), kLimit);
  const ProcessResult at_limit = run({"check", "bad.json"});
  EXPECT_TRUE(at_limit.exited && at_limit.status == 0) << at_limit.how << "\n" << at_limit.err;

  write("bad.json", study_text(kScene, std::string(kLimit + 1 - head.size(), 'x')));
  EXPECT_TRUE(OnlyError(run({"check", "bad.json"}), "bad.json: ",
                        "file too large: 16777217 bytes (the limit for a study or scene file is "
                        "16 MiB)"));
}

// n beams of `segments` segments each from ground to one tip body: a few kilobytes of text.
std::string segmented_scene(int n, long segments) {
  std::string beams;
  for (int i = 0; i < n; ++i)
    beams += std::string(i ? ", " : "") + R"({"name": "b)" + std::to_string(i) +
             R"(", "body1": "ground", "body2": "tip", "point1": [0, 0, )" + std::to_string(i) +
             R"(], "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq10",
              "segments": )" +
             std::to_string(segments) + "}";
  return R"({"materials": {"steel": {"E": 2.1e11, "G": 8.1e10, "density": 7850}},
             "sections": {"sq10": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
             "bodies": [{"name": "tip", "position": [1, 0, 0]}], "beams": [)" +
         beams + "]}";
}

TEST_F(HostileInput, SegmentsAddUpOverAScene) {
  // Each beam alone is within the limit; 20 of them would build 2e6 bodies (seconds and
  // gigabytes from 4 kB of text).
  const std::string many = study_text(segmented_scene(20, 100000));
  ASSERT_LT(many.size(), 5000u);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(OnlyError(check(many), "bad.json:/scene/beams/1/segments: ",
                        "at most 100000 segments in a scene, all beams together (the beams before "
                        "this one have 100000)"));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
  // Up to the limit, all together.
  const ProcessResult r = check(study_text(segmented_scene(2, 50000)));
  EXPECT_TRUE(r.exited && r.status == 0) << r.how << "\n" << r.err;
  EXPECT_EQ(r.out.rfind("bad.json: ok (99999 bodies, 100000 beams, 0 rails, 1299987 states", 0), 0u)
      << r.out;
}

TEST_F(HostileInput, DeeplyNestedObjectsAndSceneFiles) {
  // Arrays 100000 deep are in bad_input_test.cpp; objects take another path through the parser.
  std::string deep;
  for (int i = 0; i < 100000; ++i) deep += "{\"a\":";
  deep += "1";
  deep += std::string(100000, '}');
  // The 257th "{" starts at column 256 * 5 + 1.
  EXPECT_TRUE(OnlyError(check(deep), "bad.json: ",
                        "invalid JSON at line 1, column 1281: nesting deeper than 256 levels"));

  write("parts/deep.json", std::string(100000, '[') + std::string(100000, ']'));
  EXPECT_TRUE(OnlyError(check(study_text(quoted("parts/deep.json"))), "parts/deep.json: ",
                        "invalid JSON at line 1, column 257: nesting deeper than 256 levels"));

  // Brackets inside a string are text, not nesting.
  const ProcessResult r = check(study_text(kScene, std::string(100000, '[')));
  EXPECT_TRUE(r.exited && r.status == 0) << r.how << "\n" << r.err;
}

TEST_F(HostileInput, InvalidUtf8) {
  // In a string value, in a key, and outside any string; the bytes are not echoed raw.
  std::string text = study_text(kScene);
  text.replace(text.find("hostile"), 7, "host\xff\xfeile");
  EXPECT_TRUE(OnlyError(check(text), "bad.json: ",
                        "invalid JSON at line 1, column 15: syntax error while parsing value - "
                        "invalid string: ill-formed UTF-8 byte; last read: '\"host\\xff'"));
  text = study_text(kScene);
  text.replace(text.find("\"name\""), 6, "\"na\xc3me\"");
  EXPECT_TRUE(OnlyError(check(text), "bad.json: ",
                        "invalid JSON at line 1, column 6: syntax error while parsing object key "
                        "- invalid string: ill-formed UTF-8 byte; last read: '\"na\\xc3m'"));
  EXPECT_TRUE(OnlyError(check("{\"name\": \xe2\x82}"), "bad.json: ",
                        "invalid JSON at line 1, column 10: syntax error while parsing value - "
                        "invalid literal"));
  // A lone surrogate escape is not a character either.
  EXPECT_TRUE(OnlyError(check(study_text(kScene, "\\ud800")), "bad.json: ",
                        "surrogate U+D800..U+DBFF must be followed by U+DC00..U+DFFF"));
  for (const std::string& line : lines_of(check(text).err))
    for (const char c : line) EXPECT_LT(static_cast<unsigned char>(c), 0x80u) << line;
}

TEST_F(HostileInput, NulBytes) {
  // The parser would take a NUL for the end of the text: "unexpected end of input" here, and
  // whatever follows a complete document ignored.
  std::string text = study_text(kScene);
  text.insert(text.find("\"scene\""), 1, '\0');
  const ProcessResult r = check(text);
  EXPECT_TRUE(OnlyError(r, "bad.json: ",
                        "invalid JSON at line 1, column 47: a NUL byte (JSON text cannot contain "
                        "one)"));
  EXPECT_EQ(r.err.find('\0'), std::string::npos) << "a raw NUL reached the terminal";
  EXPECT_TRUE(OnlyError(check(std::string(1000, '\0')),
                        "bad.json: ", "invalid JSON at line 1, column 1: a NUL byte"));
  text = study_text(kScene) + "\n";
  text += std::string("\0 trailing text", 15);
  EXPECT_TRUE(
      OnlyError(check(text), "bad.json: ", "invalid JSON at line 11, column 1: a NUL byte"));
  // An escaped NUL is valid JSON, but a name with it would name another output folder.
  text = study_text(kScene);
  text.replace(text.find("\"hostile\""), 9, R"("a\u0000b")");
  EXPECT_TRUE(OnlyError(check(text), "bad.json:/name: ",
                        "must be a non-empty name without path separators or control characters"));
}

TEST_F(HostileInput, EmptyFiles) {
  EXPECT_TRUE(
      OnlyError(check(""), "bad.json: ",
                "invalid JSON at line 1, column 1: the file is empty (expected a JSON object)"));
  write("parts/empty.json", "");
  EXPECT_TRUE(
      OnlyError(check(study_text(quoted("parts/empty.json"))), "parts/empty.json: ",
                "invalid JSON at line 1, column 1: the file is empty (expected a JSON object)"));
  // Only white space: the parser's own message, with where the text ended.
  EXPECT_TRUE(OnlyError(check(" \n\t\n"), "bad.json: ",
                        "invalid JSON at line 3, column 1: syntax error while parsing value - "
                        "unexpected end of input"));
}

}  // namespace
}  // namespace beamrail
