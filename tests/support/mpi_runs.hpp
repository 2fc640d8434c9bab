// Running studies under mpirun from a test (tests/optimizer/mpi_job_test.cpp,
// mpi_failures_test.cpp): a temporary folder, the study written into it, the beamrail binary
// (BEAMRAIL_EXECUTABLE, defined by the test's target) run in one process or under mpirun
// (BEAMRAIL_MPIEXEC), and the tables read back as text for comparison. The study: a 1.2 m steel
// tube cantilever with a 3 kg tip body under a side load, as a sweep or an optimization.
#pragma once

#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/support/run_process.hpp"

#ifndef BEAMRAIL_EXECUTABLE
#error "BEAMRAIL_EXECUTABLE must name the beamrail binary"
#endif
#ifndef BEAMRAIL_MPIEXEC
#error "BEAMRAIL_MPIEXEC must name mpirun"
#endif

namespace beamrail::testing {

namespace mpi_runs_fs = std::filesystem;

inline std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (char c : line) {
    if (c == '"') quoted = !quoted;
    if (c == ',' && !quoted)
      out.emplace_back();
    else
      out.back() += c;
  }
  return out;
}

// The rows of a CSV table (header first), each without its wall_s field.
inline std::vector<std::vector<std::string>> rows_without_wall(const mpi_runs_fs::path& path) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(path);
  std::string line;
  long wall = -1;
  while (std::getline(in, line)) {
    std::vector<std::string> f = split_fields(line);
    if (rows.empty())
      for (size_t i = 0; i < f.size(); ++i)
        if (f[i] == "wall_s") wall = static_cast<long>(i);
    if (wall >= 0 && wall < static_cast<long>(f.size())) f.erase(f.begin() + wall);
    rows.push_back(std::move(f));
  }
  return rows;
}

// The index of column `name` in a table's header row (its size when it has none).
inline size_t column_of(const std::vector<std::string>& header, const std::string& name) {
  for (size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return i;
  return header.size();
}

// The tube cantilever with static and modal responses over its outer diameter and wall, under
// the study `plan`. A wall thicker than the tube's radius makes a design invalid.
inline nlohmann::json tube_sweep(const nlohmann::json& plan) {
  nlohmann::json s = nlohmann::json::parse(R"({
    "name": "tube_sweep",
    "scene": {
      "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
      "sections": {"tube": {"shape": "tube", "outer_diameter": 0.04, "wall": 0.003}},
      "bodies": [{"name": "tip", "mass": 3.0, "inertia": [2e-3, 2e-3, 2e-3],
                  "position": [1.2, 0, 0]}],
      "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
                 "point2": [1.2, 0, 0], "point3": [0, 1, 0], "material": "steel",
                 "section": "tube", "segments": 4}],
      "loads": [{"type": "force", "body": "tip", "value": [0, -200, 0]}]
    },
    "analyses": [{"type": "static"}, {"type": "modal", "modes": 2, "about": "initial"}],
    "responses": {
      "f1": {"quantity": "frequency", "mode": 1},
      "deflection": {"quantity": "displacement", "body": "tip", "direction": [0, -1, 0]},
      "stress": {"quantity": "max_stress"},
      "mass": {"quantity": "mass"}
    }
  })");
  s["study"] = plan;
  return s;
}

// The tube cantilever as an optimization: the lightest tube whose first frequency is at least
// 25 Hz and whose tip deflects at most 5 mm, from 4 starts (Latin-hypercube points). A wall
// thicker than the tube's radius is an invalid design: a row of the history with its status.
inline nlohmann::json tube_optimization(const std::string& algorithm, const std::string& gradient) {
  nlohmann::json plan =
      nlohmann::json::parse(R"({"type": "optimize", "objective": {"minimize": "mass"},
      "constraints": [{"response": "f1", ">=": 25}, {"response": "deflection", "<=": 0.005}],
      "starts": 4, "seed": 3, "max_evaluations": 40, "variables": [
      {"name": "outer_diameter", "pointer": "/scene/sections/tube/outer_diameter",
       "lower": 0.02, "upper": 0.08},
      {"name": "wall", "pointer": "/scene/sections/tube/wall", "lower": 0.001,
       "upper": 0.02}]})");
  plan["algorithm"] = algorithm;
  if (!gradient.empty()) plan["gradient"] = gradient;
  return tube_sweep(plan);
}

// summary.json without what may differ between runs of the same study: times and the ranks and
// threads that ran it, and what each rank did.
inline nlohmann::json without_times(nlohmann::json summary) {
  for (const char* key : {"wall_seconds", "evaluations_per_second", "ranks", "threads",
                          "starts_per_rank", "designs_per_rank", "scheduler_seconds"})
    summary.erase(key);
  return summary;
}

// A test in a temporary folder of its own, removed at its end, running BEAMRAIL_EXECUTABLE in it.
class MpiStudyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (mpi_runs_fs::temp_directory_path() / "beamrail_mpi_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    mpi_runs_fs::remove_all(dir_, ec);
  }

  mpi_runs_fs::path write_study(const std::string& name, const nlohmann::json& study) {
    std::ofstream(dir_ / name, std::ios::binary) << study.dump(2) << "\n";
    return dir_ / name;
  }

  // mpirun's arguments for `ranks` ranks of `beamrail args...`: more ranks than cores are
  // allowed, threads are not bound to one core, and root may run it (CI runs as root).
  static std::vector<std::string> mpirun_args(int ranks, const std::vector<std::string>& args) {
    std::vector<std::string> a{"--oversubscribe", "--bind-to", "none", "-n", std::to_string(ranks)};
    if (geteuid() == 0) a.insert(a.begin(), "--allow-run-as-root");
    a.push_back(BEAMRAIL_EXECUTABLE);
    a.insert(a.end(), args.begin(), args.end());
    return a;
  }

  ProcessResult run_alone(const std::vector<std::string>& args) {
    return run_process(BEAMRAIL_EXECUTABLE, args, dir_, std::chrono::seconds(120));
  }
  ProcessResult run_mpi(int ranks, const std::vector<std::string>& args) {
    return run_process(BEAMRAIL_MPIEXEC, mpirun_args(ranks, args), dir_, std::chrono::seconds(120));
  }

  mpi_runs_fs::path dir_;
};

}  // namespace beamrail::testing
