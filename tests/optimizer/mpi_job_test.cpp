// Design studies over MPI ranks (optimizer/batch/mpi_job.hpp) through the real command line:
// `mpirun -n R beamrail run` writes the tables that one process writes (every column but wall_s
// equal, as text), whatever the ranks and threads; a design that fails on a rank is a row like
// any other; summary.json records the ranks and threads; a job stopped part-way resumes under
// mpirun with each design once.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/run_process.hpp"

#ifndef BEAMRAIL_EXECUTABLE
#error "BEAMRAIL_EXECUTABLE must name the beamrail binary"
#endif
#ifndef BEAMRAIL_MPIEXEC
#error "BEAMRAIL_MPIEXEC must name mpirun"
#endif

namespace beamrail {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using testing::Process;
using testing::ProcessResult;
using testing::read_text;

std::vector<std::string> split_fields(const std::string& line) {
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
std::vector<std::vector<std::string>> rows_without_wall(const fs::path& path) {
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

// A 1.2 m steel tube cantilever with a 3 kg tip body under a side load: static and modal
// responses over its outer diameter and wall. A wall of 12 mm on a tube of 20 mm is more than its
// radius: that design is invalid.
Json tube_sweep(const Json& plan) {
  Json s = Json::parse(R"({
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

Json grid_plan() {
  return Json::parse(R"({"type": "sweep", "sampling": "grid", "variables": [
      {"name": "outer_diameter", "pointer": "/scene/sections/tube/outer_diameter",
       "lower": 0.02, "upper": 0.06, "count": 5},
      {"name": "wall", "pointer": "/scene/sections/tube/wall",
       "values": [0.001, 0.003, 0.012]}]})");
}

Json lhs_plan() {
  return Json::parse(R"({"type": "sweep", "sampling": "lhs", "samples": 24, "seed": 7,
      "variables": [
      {"name": "outer_diameter", "pointer": "/scene/sections/tube/outer_diameter",
       "lower": 0.02, "upper": 0.06},
      {"name": "wall", "pointer": "/scene/sections/tube/wall", "lower": 0.001,
       "upper": 0.012}]})");
}

class MpiRun : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "beamrail_mpi_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  fs::path write_study(const std::string& name, const Json& study) {
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
    return testing::run_process(BEAMRAIL_EXECUTABLE, args, dir_, std::chrono::seconds(120));
  }
  ProcessResult run_mpi(int ranks, const std::vector<std::string>& args) {
    return testing::run_process(BEAMRAIL_MPIEXEC, mpirun_args(ranks, args), dir_,
                                std::chrono::seconds(120));
  }

  // Runs the study in one process with -j 1 (into "alone") and under mpirun (into "mpi"), and
  // compares the tables.
  void expect_same_tables(const Json& study, int ranks, int threads) {
    const fs::path file = write_study("study.json", study);
    const ProcessResult alone =
        run_alone({"run", file.string(), "-o", "alone", "-j", "1", "--quiet"});
    ASSERT_TRUE(alone.exited && alone.status == 0) << alone.how << "\n" << alone.err;
    const ProcessResult mpi = run_mpi(
        ranks, {"run", file.string(), "-o", "mpi", "-j", std::to_string(threads), "--quiet"});
    ASSERT_TRUE(mpi.exited && mpi.status == 0) << mpi.how << "\n" << mpi.out << mpi.err;
    const auto expected = rows_without_wall(dir_ / "alone" / "samples.csv");
    const auto got = rows_without_wall(dir_ / "mpi" / "samples.csv");
    ASSERT_EQ(got.size(), expected.size());
    for (size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], expected[i]) << "row " << i;
    const Json one = Json::parse(read_text(dir_ / "alone" / "summary.json"));
    const Json many = Json::parse(read_text(dir_ / "mpi" / "summary.json"));
    EXPECT_EQ(one["ranks"], 1);
    EXPECT_EQ(one["threads"], 1);
    EXPECT_EQ(many["ranks"], ranks);
    EXPECT_EQ(many["threads"], threads);
    EXPECT_EQ(many["status"], "ok");
    EXPECT_EQ(many["failed_or_invalid"], one["failed_or_invalid"]);
    EXPECT_EQ(many["evaluated_now"], expected.size() - 1);
  }

  fs::path dir_;
};

// 15 designs of a grid on 2 ranks, 3 of them invalid (a wall thicker than the tube's radius): the
// invalid designs are rows with their status and message, as in one process.
TEST_F(MpiRun, AGridSweepOnTwoRanksWritesTheTablesOfOneProcess) {
  ASSERT_NO_FATAL_FAILURE(expect_same_tables(tube_sweep(grid_plan()), 2, 1));
  const auto rows = rows_without_wall(dir_ / "mpi" / "samples.csv");
  size_t status = 0;
  for (size_t i = 0; i < rows[0].size(); ++i)
    if (rows[0][i] == "status") status = i;
  std::set<std::string> statuses;
  long not_ok = 0;
  for (size_t i = 1; i < rows.size(); ++i) {
    statuses.insert(rows[i][status]);
    not_ok += rows[i][status] != "ok";
  }
  EXPECT_TRUE(statuses.count("ok"));
  EXPECT_GE(not_ok, 1) << "the sweep was meant to hold a failing design";
}

// A Latin hypercube on 3 ranks of 2 threads each.
TEST_F(MpiRun, AnLhsSweepOnThreeRanksOfTwoThreadsWritesTheTablesOfOneProcess) {
  ASSERT_NO_FATAL_FAILURE(expect_same_tables(tube_sweep(lhs_plan()), 3, 2));
}

// A 40-design sweep of short transients under mpirun, stopped part-way by SIGTERM to mpirun (as
// a cluster's scheduler ends a job), then resumed under mpirun: the table holds each design
// once, equal to one process's.
TEST_F(MpiRun, AJobStoppedPartWayResumesUnderMpirunWithEachDesignOnce) {
  Json study = tube_sweep(Json::parse(R"({"type": "sweep", "variables": [{"name": "load",
      "pointer": "/scene/loads/0/value/1", "lower": -300, "upper": -100, "count": 40}]})"));
  study["analyses"] = Json::parse(R"([{"type": "transient", "t_end": 0.05, "output_step": 0.001,
      "integrator": {"rtol": 1e-9, "atol": 1e-12}}])");
  study["responses"] = Json::parse(R"({"peak": {"quantity": "peak_displacement",
      "body": "tip", "direction": [0, 1, 0]}})");
  const fs::path file = write_study("study.json", study);
  const fs::path samples = dir_ / "mpi" / "samples.csv";
  auto rows_now = [&] {
    std::error_code ec;
    if (!fs::exists(samples, ec)) return size_t{0};
    const std::string text = read_text(samples);
    return static_cast<size_t>(std::count(text.begin(), text.end(), '\n'));
  };
  {
    Process p(BEAMRAIL_MPIEXEC,
              mpirun_args(2, {"run", file.string(), "-o", "mpi", "-j", "1", "--quiet"}), dir_);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (rows_now() < 4 && p.alive() && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    p.kill(SIGTERM);
    const ProcessResult r = p.wait(std::chrono::seconds(60));
    std::printf("stopped: %s\n%s", r.how.c_str(), r.err.c_str());
  }
  const size_t kept = rows_now();
  EXPECT_GE(kept, 4u);
  const ProcessResult resumed =
      run_mpi(2, {"run", file.string(), "-o", "mpi", "-j", "1", "--quiet", "--resume"});
  ASSERT_TRUE(resumed.exited && resumed.status == 0) << resumed.how << "\n" << resumed.err;
  const ProcessResult alone =
      run_alone({"run", file.string(), "-o", "alone", "-j", "1", "--quiet"});
  ASSERT_TRUE(alone.exited && alone.status == 0) << alone.how << "\n" << alone.err;
  const auto expected = rows_without_wall(dir_ / "alone" / "samples.csv");
  const auto got = rows_without_wall(samples);
  ASSERT_EQ(got.size(), 41u);
  ASSERT_EQ(got.size(), expected.size());
  for (size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], expected[i]) << "row " << i;
  const Json summary = Json::parse(read_text(dir_ / "mpi" / "summary.json"));
  EXPECT_EQ(summary["resumed_from_table"].get<size_t>() + summary["evaluated_now"].get<size_t>(),
            40u);
  EXPECT_EQ(summary["ranks"], 2);
}

}  // namespace
}  // namespace beamrail
