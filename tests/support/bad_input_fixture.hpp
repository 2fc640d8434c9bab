// The fixture of the bad-input tests (tests/optimizer/bad_input_*test.cpp): a valid study with
// every kind of scene part, the real command line run on a broken copy of it in a temporary
// folder, with a time limit (a hang fails like a crash), and the checks of its stderr.
#pragma once

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

namespace beamrail::bad_input {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using Pointer = Json::json_pointer;

// A valid study with every kind of scene part: two free bodies, a beam, a rail, a force with a
// ramp and a torque with a table, a transient analysis with an integrator, two responses.
inline constexpr const char* kBaseStudy = R"({
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

inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

inline std::string read_text(const fs::path& path) {
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
inline ::testing::AssertionResult HasError(const Result& r, const std::string& prefix,
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
inline ::testing::AssertionResult HasOnlyError(const Result& r, const std::string& prefix,
                                               const std::string& phrase) {
  auto result = HasError(r, prefix, phrase);
  if (!result) return result;
  const size_t n = lines_of(r.err).size();
  if (n != 1)
    return ::testing::AssertionFailure() << "expected exactly one problem, got " << n << ":\n"
                                         << r.err;
  return ::testing::AssertionSuccess();
}

inline size_t line_count(const Result& r) { return lines_of(r.err).size(); }

}  // namespace beamrail::bad_input
