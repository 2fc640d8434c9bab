// Design studies over MPI ranks (optimizer/batch/mpi_job.hpp) through the real command line:
// `mpirun -n R beamrail run` writes the tables that one process writes (every column but wall_s
// equal, as text), whatever the ranks and threads; a design that fails on a rank is a row like
// any other; summary.json records the ranks and threads; a job stopped part-way resumes under
// mpirun with each design once.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/mpi_runs.hpp"
#include "tests/support/run_process.hpp"

namespace beamrail {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using testing::MpiStudyTest;
using testing::Process;
using testing::ProcessResult;
using testing::read_text;
using testing::rows_without_wall;
using testing::tube_optimization;
using testing::tube_sweep;
using testing::without_times;

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

// The processes descended from `pid` (its children, theirs, ...), read from /proc.
std::vector<pid_t> descendants(pid_t pid) {
  std::map<pid_t, std::vector<pid_t>> children;
  std::error_code ec;
  for (fs::directory_iterator it("/proc", ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream in(it->path() / "stat");
    std::string line;
    std::getline(in, line);
    const size_t close = line.rfind(')');
    if (close == std::string::npos || close + 2 >= line.size()) continue;
    std::istringstream rest(line.substr(close + 2));
    char state = 0;
    pid_t parent = 0;
    rest >> state >> parent;
    children[parent].push_back(static_cast<pid_t>(std::stol(name)));
  }
  std::vector<pid_t> out, todo{pid};
  while (!todo.empty()) {
    const pid_t p = todo.back();
    todo.pop_back();
    for (pid_t c : children[p]) out.push_back(c), todo.push_back(c);
  }
  return out;
}

// Whether a process runs still (exists and is not a zombie).
bool runs(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(in, line)) return false;
  const size_t close = line.rfind(')');
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] != 'Z';
}

// Ends an mpirun job as a failing node or a scheduler's hard kill does: mpirun and every process
// it started are stopped at once (SIGSTOP, so that none writes another byte), then killed
// (SIGKILL); killing mpirun alone would not do (its ranks run on). Returns when none runs.
void kill_whole_job(Process& mpirun) {
  std::vector<pid_t> job = descendants(mpirun.pid());
  job.push_back(mpirun.pid());
  for (pid_t pid : job) ::kill(pid, SIGSTOP);
  for (pid_t pid : job) ::kill(pid, SIGKILL);
  const ProcessResult r = mpirun.wait(std::chrono::seconds(30));
  EXPECT_EQ(r.signal, SIGKILL) << r.how << "\n" << r.err;
  EXPECT_GE(job.size(), 3u) << "mpirun and its 2 ranks";
  const auto gone = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  for (pid_t pid : job)
    while (runs(pid) && std::chrono::steady_clock::now() < gone)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
  for (pid_t pid : job) ASSERT_FALSE(runs(pid)) << "process " << pid << " outlived SIGKILL";
}

// The newline-terminated lines of a table (the header and the whole rows), 0 when it is absent.
size_t lines_of(const fs::path& table) {
  std::error_code ec;
  if (!fs::exists(table, ec)) return 0;
  const std::string text = read_text(table);
  return static_cast<size_t>(std::count(text.begin(), text.end(), '\n'));
}

class MpiRun : public MpiStudyTest {
 protected:
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

  // Waits until `table` has `lines` lines (the header and whole rows), `p` has ended, or 60 s
  // have passed.
  static void wait_for_lines(Process& p, const fs::path& table, size_t lines) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (lines_of(table) < lines && p.alive() && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }

  // Resumes the stopped job of `file` in "mpi" on 2 ranks and checks that its samples.csv (a
  // header and `designs` rows) equals the table one process writes into "alone"; returns the
  // resumed job's summary.
  Json resume_and_compare(const fs::path& file, size_t designs) {
    const ProcessResult resumed =
        run_mpi(2, {"run", file.string(), "-o", "mpi", "-j", "1", "--quiet", "--resume"});
    EXPECT_TRUE(resumed.exited && resumed.status == 0) << resumed.how << "\n" << resumed.err;
    const ProcessResult alone =
        run_alone({"run", file.string(), "-o", "alone", "-j", "1", "--quiet"});
    EXPECT_TRUE(alone.exited && alone.status == 0) << alone.how << "\n" << alone.err;
    const auto expected = rows_without_wall(dir_ / "alone" / "samples.csv");
    const auto got = rows_without_wall(dir_ / "mpi" / "samples.csv");
    EXPECT_EQ(got.size(), designs + 1);
    EXPECT_EQ(got, expected);
    const Json summary = Json::parse(read_text(dir_ / "mpi" / "summary.json"));
    EXPECT_EQ(summary["ranks"], 2);
    return summary;
  }
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

// 12 designs on 3 ranks, 9 of them invalid (walls of 13, 15 and 20 mm on tubes of 10 to 12 mm
// radius): whichever rank evaluates an invalid design, it is a row with its status, and the other
// designs go on, as in one process. More designs on ranks 1 and 2 than there are valid ones: at
// least one invalid design was evaluated on a rank other than 0.
TEST_F(MpiRun, InvalidDesignsOnOtherRanksAreRowsAndTheSweepGoesOn) {
  Json plan = grid_plan();
  plan["variables"][0]["lower"] = 0.02;
  plan["variables"][0]["upper"] = 0.024;
  plan["variables"][0]["count"] = 3;
  plan["variables"][1]["values"] = Json::array({0.003, 0.013, 0.015, 0.02});
  ASSERT_NO_FATAL_FAILURE(expect_same_tables(tube_sweep(plan), 3, 1));
  const auto rows = rows_without_wall(dir_ / "mpi" / "samples.csv");
  size_t status = 0;
  for (size_t i = 0; i < rows[0].size(); ++i)
    if (rows[0][i] == "status") status = i;
  std::map<std::string, long> count;
  for (size_t i = 1; i < rows.size(); ++i) ++count[rows[i][status]];
  EXPECT_EQ(count["ok"], 3);
  EXPECT_EQ(count["invalid"], 9);
  const Json many = Json::parse(read_text(dir_ / "mpi" / "summary.json"));
  ASSERT_EQ(many["designs_per_rank"].size(), 3u);
  const long others =
      many["designs_per_rank"][1].get<long>() + many["designs_per_rank"][2].get<long>();
  EXPECT_GT(others, count["ok"]) << many["designs_per_rank"];
  EXPECT_EQ(others + many["designs_per_rank"][0].get<long>(), 12);
}

// A Latin hypercube on 3 ranks of 2 threads each.
TEST_F(MpiRun, AnLhsSweepOnThreeRanksOfTwoThreadsWritesTheTablesOfOneProcess) {
  ASSERT_NO_FATAL_FAILURE(expect_same_tables(tube_sweep(lhs_plan()), 3, 2));
}

// A sweep of `count` short transients of the tube over its side load.
Json transient_load_sweep(int count) {
  Json study = tube_sweep({{"type", "sweep"},
                           {"variables", Json::array({{{"name", "load"},
                                                       {"pointer", "/scene/loads/0/value/1"},
                                                       {"lower", -300},
                                                       {"upper", -100},
                                                       {"count", count}}})}});
  study["analyses"] = Json::parse(R"([{"type": "transient", "t_end": 0.05, "output_step": 0.001,
      "integrator": {"rtol": 1e-9, "atol": 1e-12}}])");
  study["responses"] = Json::parse(R"({"peak": {"quantity": "peak_displacement",
      "body": "tip", "direction": [0, 1, 0]}})");
  return study;
}

// A 120-design sweep of short transients under mpirun, stopped part-way by SIGTERM to mpirun (as
// a cluster's scheduler ends a job), then resumed under mpirun: the table holds each design
// once, equal to one process's.
TEST_F(MpiRun, AJobStoppedPartWayResumesUnderMpirunWithEachDesignOnce) {
  const fs::path file = write_study("study.json", transient_load_sweep(120));
  const fs::path samples = dir_ / "mpi" / "samples.csv";
  {
    Process p(BEAMRAIL_MPIEXEC,
              mpirun_args(2, {"run", file.string(), "-o", "mpi", "-j", "1", "--quiet"}), dir_);
    wait_for_lines(p, samples, 4);
    p.kill(SIGTERM);
    const ProcessResult r = p.wait(std::chrono::seconds(60));
    std::printf("stopped: %s\n%s", r.how.c_str(), r.err.c_str());
    // The run says it was interrupted and how to go on; mpirun's own exit status, signalled
    // itself, is Open MPI's (1), whatever the ranks return (rank 0: 143).
    EXPECT_NE(r.err.find("interrupted by SIGTERM"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--resume"), std::string::npos) << r.err;
  }
  EXPECT_EQ(Json::parse(read_text(dir_ / "mpi" / "summary.json"))["status"], "interrupted");
  const size_t kept = lines_of(samples);
  EXPECT_GE(kept, 4u);
  ASSERT_LT(kept, 121u) << "the job was meant to be stopped part-way";
  const Json summary = resume_and_compare(file, 120);
  EXPECT_EQ(summary["resumed_from_table"].get<size_t>(), kept - 1);
  EXPECT_EQ(summary["evaluated_now"].get<size_t>(), 121 - kept);
}

// A 120-design sweep of short transients under mpirun, ended part-way as a failing node or a
// scheduler's hard kill ends a job (kill_whole_job; killing mpirun alone would not do: the ranks
// run on and finish the sweep). Resumed under mpirun, the job evaluates exactly the designs whose
// rows were not in samples.csv, and the table equals one process's: nothing lost, nothing twice.
TEST_F(MpiRun, AJobKilledWholeResumesUnderMpirunWithNothingLostOrDuplicated) {
  const fs::path file = write_study("study.json", transient_load_sweep(120));
  const fs::path samples = dir_ / "mpi" / "samples.csv";
  {
    Process p(BEAMRAIL_MPIEXEC,
              mpirun_args(2, {"run", file.string(), "-o", "mpi", "-j", "1", "--quiet"}), dir_);
    wait_for_lines(p, samples, 11);
    ASSERT_NO_FATAL_FAILURE(kill_whole_job(p));
  }
  const size_t kept = lines_of(samples);  // the header and the whole rows
  EXPECT_GE(kept, 11u);
  ASSERT_LT(kept, 121u) << "the job was meant to be killed part-way";
  const Json summary = resume_and_compare(file, 120);
  EXPECT_EQ(summary["resumed_from_table"].get<size_t>(), kept - 1);
  EXPECT_EQ(summary["evaluated_now"].get<size_t>(), 121 - kept);
}

// A work-precision study (3 methods at 2 tolerances on a short transient of the tube) on 3 ranks:
// the runs go one at a time to each rank, which measures its run against the reference rank 0
// sends; work_precision.csv is one process's apart from wall_s.
TEST_F(MpiRun, AWorkPrecisionStudyOnThreeRanksWritesTheTableOfOneProcess) {
  Json study = tube_sweep(Json::parse(R"({"type": "work_precision",
      "methods": [{"method": "bdf"}, {"method": "dirk"},
                  {"method": "erk", "table": "VERNER_8_5_6"}],
      "rtols": [1e-4, 1e-7], "target_error": 1e-5})"));
  study["analyses"] = Json::parse(R"([{"type": "transient", "t_end": 0.02, "output_step": 2e-4}])");
  study.erase("responses");
  const fs::path file = write_study("study.json", study);
  const ProcessResult alone = run_alone({"run", file.string(), "-o", "alone", "--quiet"});
  ASSERT_TRUE(alone.exited && alone.status == 0) << alone.how << "\n" << alone.err;
  const ProcessResult mpi = run_mpi(3, {"run", file.string(), "-o", "mpi", "--quiet"});
  ASSERT_TRUE(mpi.exited && mpi.status == 0) << mpi.how << "\n" << mpi.out << mpi.err;
  EXPECT_EQ(mpi.err.find("rank 0 alone"), std::string::npos) << mpi.err;
  const auto expected = rows_without_wall(dir_ / "alone" / "work_precision.csv");
  const auto got = rows_without_wall(dir_ / "mpi" / "work_precision.csv");
  ASSERT_EQ(expected.size(), 7u);
  ASSERT_EQ(got.size(), expected.size());
  for (size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], expected[i]) << "row " << i;
  // The ranks measured rotations too: the orientations of the reference reached them.
  const size_t rotation = static_cast<size_t>(
      std::find(expected[0].begin(), expected[0].end(), "rotation_error") - expected[0].begin());
  ASSERT_LT(rotation, expected[0].size());
  for (size_t i = 1; i < got.size(); ++i) {
    ASSERT_LT(rotation, got[i].size());
    const double e = std::stod(got[i][rotation]);
    EXPECT_TRUE(std::isfinite(e) && e > 0.0) << "row " << i << ": " << got[i][rotation];
  }
  const Json one = Json::parse(read_text(dir_ / "alone" / "summary.json"));
  const Json many = Json::parse(read_text(dir_ / "mpi" / "summary.json"));
  EXPECT_EQ(one["ranks"], 1);
  EXPECT_FALSE(one.contains("runs_per_rank"));
  EXPECT_EQ(many["ranks"], 3);
  EXPECT_EQ(many["status"], "ok");
  EXPECT_EQ(many["runs"], 6);
  EXPECT_EQ(many["reference"]["steps"], one["reference"]["steps"]);
  // Ranks 1 and 2 get a run each before any run can end; rank 0 runs what is left.
  ASSERT_EQ(many["runs_per_rank"].size(), 3u);
  EXPECT_GE(many["runs_per_rank"][1].get<long>(), 1);
  EXPECT_GE(many["runs_per_rank"][2].get<long>(), 1);
  EXPECT_EQ(many["runs_per_rank"][0].get<long>() + many["runs_per_rank"][1].get<long>() +
                many["runs_per_rank"][2].get<long>(),
            6);
}

// A sensitivity study of the tube with its check on 3 ranks: the 4 designs of the central
// differences go to the ranks, and sensitivities.csv (derivatives and differences) and summary.json
// (times and ranks aside) are those of one process.
TEST_F(MpiRun, ASensitivityCheckOnThreeRanksWritesTheTablesOfOneProcess) {
  const Json study = tube_sweep(Json::parse(R"({"type": "sensitivity", "check": true,
      "variables": [
      {"name": "outer_diameter", "pointer": "/scene/sections/tube/outer_diameter"},
      {"name": "wall", "pointer": "/scene/sections/tube/wall"}]})"));
  const fs::path file = write_study("study.json", study);
  const ProcessResult alone =
      run_alone({"run", file.string(), "-o", "alone", "-j", "1", "--quiet"});
  ASSERT_TRUE(alone.exited && alone.status == 0) << alone.how << "\n" << alone.err;
  const ProcessResult mpi = run_mpi(3, {"run", file.string(), "-o", "mpi", "-j", "1", "--quiet"});
  ASSERT_TRUE(mpi.exited && mpi.status == 0) << mpi.how << "\n" << mpi.out << mpi.err;
  EXPECT_EQ(mpi.err.find("rank 0 alone"), std::string::npos) << mpi.err;
  const auto expected = rows_without_wall(dir_ / "alone" / "sensitivities.csv");
  const auto got = rows_without_wall(dir_ / "mpi" / "sensitivities.csv");
  ASSERT_EQ(expected.size(), 1u + 4u * 2u);  // 4 responses x 2 variables
  ASSERT_EQ(got.size(), expected.size());
  for (size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], expected[i]) << "row " << i;
  // The check computed a difference for every row (no empty or nan field).
  for (size_t i = 1; i < got.size(); ++i)
    for (const std::string& field : got[i]) EXPECT_TRUE(!field.empty() && field != "nan") << i;
  Json one = Json::parse(read_text(dir_ / "alone" / "summary.json"));
  Json many = Json::parse(read_text(dir_ / "mpi" / "summary.json"));
  EXPECT_EQ(one["ranks"], 1);
  EXPECT_EQ(many["ranks"], 3);
  EXPECT_EQ(many["status"], "ok");
  for (const char* key : {"design_seconds", "check_seconds"}) one.erase(key), many.erase(key);
  EXPECT_EQ(without_times(many), without_times(one));
}

class MpiOptimization : public MpiRun {
 protected:
  // Runs the optimization in one process with -j 1 (into "alone") and under mpirun (into "mpi"),
  // and compares history.csv, derivatives.csv, best.json and summary.json.
  void expect_same_files(const Json& study, int ranks, int threads) {
    const fs::path file = write_study("study.json", study);
    const ProcessResult alone =
        run_alone({"run", file.string(), "-o", "alone", "-j", "1", "--quiet"});
    ASSERT_TRUE(alone.exited && alone.status == 0) << alone.how << "\n" << alone.err;
    const ProcessResult mpi = run_mpi(
        ranks, {"run", file.string(), "-o", "mpi", "-j", std::to_string(threads), "--quiet"});
    ASSERT_TRUE(mpi.exited && mpi.status == 0) << mpi.how << "\n" << mpi.out << mpi.err;
    EXPECT_EQ(mpi.err.find("rank 0 alone"), std::string::npos) << mpi.err;
    for (const char* table : {"history.csv", "derivatives.csv"}) {
      EXPECT_EQ(fs::exists(dir_ / "alone" / table), fs::exists(dir_ / "mpi" / table)) << table;
      if (!fs::exists(dir_ / "alone" / table)) continue;
      const auto expected = rows_without_wall(dir_ / "alone" / table);
      const auto got = rows_without_wall(dir_ / "mpi" / table);
      ASSERT_EQ(got.size(), expected.size()) << table;
      for (size_t i = 0; i < got.size(); ++i)
        EXPECT_EQ(got[i], expected[i]) << table << " row " << i;
    }
    EXPECT_EQ(Json::parse(read_text(dir_ / "mpi" / "best.json")),
              Json::parse(read_text(dir_ / "alone" / "best.json")));
    const Json one = Json::parse(read_text(dir_ / "alone" / "summary.json"));
    const Json many = Json::parse(read_text(dir_ / "mpi" / "summary.json"));
    EXPECT_EQ(without_times(many), without_times(one));
    EXPECT_EQ(one["ranks"], 1);
    EXPECT_EQ(one["threads"], 1);
    EXPECT_FALSE(one.contains("starts_per_rank"));
    EXPECT_EQ(many["ranks"], ranks);
    EXPECT_EQ(many["threads"], threads);
    EXPECT_EQ(many["status"], "ok");
    if (!many.contains("starts_per_rank")) return;  // the ranks evaluated gradient points
    // Every rank ran starts: the first ranks - 1 go to the other ranks at once, and rank 0 takes
    // one of the 4 as soon as it starts.
    ASSERT_EQ(many["starts_per_rank"].size(), static_cast<size_t>(ranks));
    long starts = 0;
    for (const Json& n : many["starts_per_rank"]) {
      EXPECT_GE(n.get<long>(), 1) << many["starts_per_rank"];
      starts += n.get<long>();
    }
    EXPECT_EQ(starts, 4);
  }

  // How many rows of history.csv have each status.
  std::map<std::string, long> statuses(const fs::path& history) {
    const auto rows = rows_without_wall(history);
    size_t column = 0;
    for (size_t i = 0; i < rows[0].size(); ++i)
      if (rows[0][i] == "status") column = i;
    std::map<std::string, long> count;
    for (size_t i = 1; i < rows.size(); ++i) ++count[rows[i][column]];
    return count;
  }
};

// COBYLA from 4 starts on 2 ranks: the same history, best design and summary as one process,
// invalid designs included.
TEST_F(MpiOptimization, AMultiStartOptimizationOnTwoRanksWritesTheFilesOfOneProcess) {
  ASSERT_NO_FATAL_FAILURE(expect_same_files(tube_optimization("LN_COBYLA", ""), 2, 1));
  const std::map<std::string, long> count = statuses(dir_ / "mpi" / "history.csv");
  EXPECT_GE(count.count("ok") ? count.at("ok") : 0, 20);
  EXPECT_GE(count.count("invalid") ? count.at("invalid") : 0, 1)
      << "the optimization was meant to try an invalid design";
}

// SLSQP with difference gradients from 1 start on 3 ranks: the start runs on rank 0 and the 5
// designs of each call of NLopt (the point and 2 per variable) go to the ranks.
TEST_F(MpiOptimization, OneStartSpreadsTheDesignsOfItsGradientsOverThreeRanks) {
  Json study = tube_optimization("LD_SLSQP", "fd");
  study["study"]["starts"] = 1;
  study["study"]["variables"][0]["initial"] = 0.05;
  study["study"]["variables"][1]["initial"] = 0.004;
  ASSERT_NO_FATAL_FAILURE(expect_same_files(study, 3, 1));
  const Json many = Json::parse(read_text(dir_ / "mpi" / "summary.json"));
  EXPECT_FALSE(many.contains("starts_per_rank"));
  ASSERT_EQ(many["designs_per_rank"].size(), 3u);
  // Each call's points go out to ranks 1 and 2 before any can come back.
  EXPECT_GE(many["designs_per_rank"][1].get<long>(), 2);
  EXPECT_GE(many["designs_per_rank"][2].get<long>(), 2);
  long designs = 0;
  for (const Json& n : many["designs_per_rank"]) designs += n.get<long>();
  // Every design of the history but the start point (evaluated alone, on rank 0 first).
  EXPECT_EQ(designs, many["designs_in_history"].get<long>() - 1);
  EXPECT_GE(many["designs_in_history"].get<long>(), 11);
}

// SLSQP with exact gradients from 4 starts on 3 ranks of 2 threads: derivatives.csv too.
TEST_F(MpiOptimization, AnOptimizationWithExactGradientsOnThreeRanksOfTwoThreads) {
  ASSERT_NO_FATAL_FAILURE(expect_same_files(tube_optimization("LD_SLSQP", "exact"), 3, 2));
  EXPECT_TRUE(fs::exists(dir_ / "mpi" / "derivatives.csv"));
}

// An optimization of short transients from 4 starts on 2 ranks, killed whole part-way
// (kill_whole_job), then resumed under mpirun: each rank replays its start's rows, and the
// history and best design are those of an uninterrupted run in one process; only the designs
// whose rows were lost with the kill are evaluated again.
TEST_F(MpiOptimization, AnOptimizationKilledWholeResumesUnderMpirun) {
  Json study = tube_optimization("LN_COBYLA", "");
  study["analyses"] = Json::parse(R"([{"type": "transient", "t_end": 0.05, "output_step": 0.001,
      "integrator": {"rtol": 1e-9, "atol": 1e-12}}])");
  study["responses"] = Json::parse(R"({"peak": {"quantity": "peak_displacement",
      "body": "tip", "direction": [0, 1, 0]}, "mass": {"quantity": "mass"}})");
  study["study"]["constraints"] = Json::parse(R"([{"response": "peak", "<=": 0.004}])");
  study["study"]["max_evaluations"] = 30;
  const fs::path file = write_study("study.json", study);
  const fs::path history = dir_ / "mpi" / "history.csv";
  {
    Process p(BEAMRAIL_MPIEXEC,
              mpirun_args(2, {"run", file.string(), "-o", "mpi", "-j", "1", "--quiet"}), dir_);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (lines_of(history) < 41 && p.alive() && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ASSERT_NO_FATAL_FAILURE(kill_whole_job(p));
  }
  const size_t kept = lines_of(history);
  EXPECT_GE(kept, 41u);
  ASSERT_LT(kept, 121u) << "the job was meant to be killed part-way";
  EXPECT_FALSE(fs::exists(dir_ / "mpi" / "best.json"));
  const ProcessResult resumed =
      run_mpi(2, {"run", file.string(), "-o", "mpi", "-j", "1", "--quiet", "--resume"});
  ASSERT_TRUE(resumed.exited && resumed.status == 0) << resumed.how << "\n" << resumed.err;
  const ProcessResult alone =
      run_alone({"run", file.string(), "-o", "alone", "-j", "1", "--quiet"});
  ASSERT_TRUE(alone.exited && alone.status == 0) << alone.how << "\n" << alone.err;
  const auto expected = rows_without_wall(dir_ / "alone" / "history.csv");
  const auto got = rows_without_wall(history);
  ASSERT_EQ(expected.size(), 121u) << "4 starts of 30 designs";
  ASSERT_EQ(got.size(), expected.size());
  for (size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], expected[i]) << "row " << i;
  EXPECT_EQ(Json::parse(read_text(dir_ / "mpi" / "best.json")),
            Json::parse(read_text(dir_ / "alone" / "best.json")));
  const Json one = Json::parse(read_text(dir_ / "alone" / "summary.json"));
  const Json many = Json::parse(read_text(dir_ / "mpi" / "summary.json"));
  EXPECT_EQ(one["designs_simulated"], 120);
  EXPECT_EQ(many["designs_simulated"].get<size_t>(), 121 - kept);
  EXPECT_EQ(many["starts"], one["starts"]);
  EXPECT_EQ(many["ranks"], 2);
}

}  // namespace
}  // namespace beamrail
