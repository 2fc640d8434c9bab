// Analyses that throw, on ranks other than 0 of an MPI job, through the real command line: the
// binary is beamrail with faults injected into its analyses (tests/support/faulty_beamrail.cpp).
// A design whose analysis throws, a std::exception or not, is a row with status "failed" and the
// batch goes on; an optimization start whose rank fails every design is rows with that status,
// and the other starts are those of one process.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "tests/support/mpi_runs.hpp"
#include "tests/support/run_process.hpp"

namespace beamrail {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using testing::column_of;
using testing::MpiStudyTest;
using testing::ProcessResult;
using testing::read_text;
using testing::rows_without_wall;
using Rows = std::vector<std::vector<std::string>>;

class MpiFailures : public MpiStudyTest {};

// 8 designs of the tube over its side load on 3 ranks of 1 thread. The first designs go out in
// index order, 2 to each other rank, before rank 0 starts evaluating: design 0 (a load of
// -130 N, whose static analysis throws a std::runtime_error naming the rank) is evaluated on rank
// 1 and design 2 (-170 N, whose analysis throws an exception of no std::exception type, as
// muparser's are) on rank 2. Both are rows with status "failed", and every other row, the order
// and the counts are those of one process (where the same designs fail on rank 0).
TEST_F(MpiFailures, AnAnalysisThatThrowsOnAnotherRankIsAFailedRowAndTheSweepGoesOn) {
  Json study = testing::tube_sweep(Json::parse(R"({"type": "sweep", "variables": [
      {"name": "load", "pointer": "/scene/loads/0/value/1",
       "values": [-130, -100, -170, -110, -120, -140, -150, -160]}]})"));
  const fs::path file = write_study("study.json", study);
  const ProcessResult alone =
      run_alone({"run", file.string(), "-o", "alone", "-j", "1", "--quiet"});
  ASSERT_TRUE(alone.exited && alone.status == 0) << alone.how << "\n" << alone.err;
  const ProcessResult mpi = run_mpi(3, {"run", file.string(), "-o", "mpi", "-j", "1", "--quiet"});
  ASSERT_TRUE(mpi.exited && mpi.status == 0) << mpi.how << "\n" << mpi.out << mpi.err;
  const Rows expected = rows_without_wall(dir_ / "alone" / "samples.csv");
  const Rows got = rows_without_wall(dir_ / "mpi" / "samples.csv");
  ASSERT_EQ(got.size(), 9u);
  ASSERT_EQ(got.size(), expected.size());
  const size_t status = column_of(got[0], "status"), message = column_of(got[0], "message");
  ASSERT_LT(message, got[0].size());
  for (size_t i = 0; i < got.size(); ++i) {
    ASSERT_EQ(got[i].size(), expected[i].size()) << "row " << i;
    for (size_t c = 0; c < got[i].size(); ++c)
      if (!(i == 1 && c == message)) {
        EXPECT_EQ(got[i][c], expected[i][c]) << "row " << i;
      }
  }
  // Design 0: the std::exception's message, naming the rank that evaluated it.
  EXPECT_EQ(got[1][status], "failed");
  EXPECT_NE(got[1][message].find("injected fault at a load of -130 N (on rank 1)"),
            std::string::npos)
      << got[1][message];
  EXPECT_NE(expected[1][message].find("(on rank 0)"), std::string::npos) << expected[1][message];
  // Design 2: an exception of no std::exception type.
  EXPECT_EQ(got[3][status], "failed");
  EXPECT_NE(got[3][message].find("not a std::exception"), std::string::npos) << got[3][message];
  long ok = 0;
  for (size_t i = 1; i < got.size(); ++i) ok += got[i][status] == "ok";
  EXPECT_EQ(ok, 6);
  const Json many = Json::parse(read_text(dir_ / "mpi" / "summary.json"));
  EXPECT_EQ(many["status"], "ok");
  EXPECT_EQ(many["failed_or_invalid"], 2);
  EXPECT_EQ(many["evaluated_now"], 8);
  ASSERT_EQ(many["designs_per_rank"].size(), 3u);
  EXPECT_GE(many["designs_per_rank"][1].get<long>(), 2);
  EXPECT_GE(many["designs_per_rank"][2].get<long>(), 2);
}

// COBYLA from 4 starts on 2 ranks, every analysis on rank 1 throwing (a study named
// "faulty_ranks": a node whose analyses all fail). Rank 1 runs at least one start (the first
// start goes out to it at once): each design it evaluates is a row with status "failed" (or
// "invalid": its values break the study before any analysis) and the rank's message, its start
// ends with no best design, and the job goes on. The starts rank 0 ran are row for row those of
// one process (where nothing fails), and the best design is the best of the history's rows.
TEST_F(MpiFailures, AStartWhoseRankFailsEveryDesignIsFailedRowsAndTheOtherStartsGoOn) {
  Json study = testing::tube_optimization("LN_COBYLA", "");
  study["name"] = "faulty_ranks";
  const fs::path file = write_study("study.json", study);
  const ProcessResult alone =
      run_alone({"run", file.string(), "-o", "alone", "-j", "1", "--quiet"});
  ASSERT_TRUE(alone.exited && alone.status == 0) << alone.how << "\n" << alone.err;
  const ProcessResult mpi = run_mpi(2, {"run", file.string(), "-o", "mpi", "-j", "1", "--quiet"});
  ASSERT_TRUE(mpi.exited) << mpi.how << "\n" << mpi.out << mpi.err;
  const Rows expected = rows_without_wall(dir_ / "alone" / "history.csv");
  const Rows got = rows_without_wall(dir_ / "mpi" / "history.csv");
  ASSERT_GE(got.size(), 2u);
  const size_t status = column_of(got[0], "status"), message = column_of(got[0], "message");
  ASSERT_LT(message, got[0].size());
  // The rows of each start, by start number (the table is in (start, evaluation) order).
  const auto by_start = [](const Rows& rows) {
    std::map<std::string, Rows> starts;
    for (size_t i = 1; i < rows.size(); ++i) starts[rows[i][0]].push_back(rows[i]);
    return starts;
  };
  const std::map<std::string, Rows> one = by_start(expected), many = by_start(got);
  ASSERT_EQ(one.size(), 4u);
  ASSERT_EQ(many.size(), 4u);
  std::set<std::string> failed_starts;
  long thrown = 0;  // rows whose analysis threw on rank 1
  for (const auto& [start, rows] : many) {
    bool on_rank_1 = false;
    for (const auto& row : rows)
      on_rank_1 = on_rank_1 || row[message].find("(on rank 1)") != std::string::npos;
    if (!on_rank_1) {
      EXPECT_EQ(rows, one.at(start)) << "start " << start << " ran on rank 0";
      continue;
    }
    failed_starts.insert(start);
    for (const auto& row : rows) {
      // Start 1's first design was evaluated on rank 0 before the starts went out.
      if (start == "1" && row[1] == "1") continue;
      // A design whose values break the study (a wall thicker than the radius) is invalid before
      // any analysis runs; every other design's analysis threw.
      if (row[status] == "invalid") continue;
      EXPECT_EQ(row[status], "failed") << "start " << start << " evaluation " << row[1];
      ++thrown;
      EXPECT_NE(row[message].find("injected fault: every analysis on this rank throws (on rank 1)"),
                std::string::npos)
          << row[message];
    }
  }
  EXPECT_GE(failed_starts.size(), 1u) << "rank 1 was meant to run a start";
  EXPECT_GE(thrown, 1);
  EXPECT_LE(failed_starts.size(), 3u) << "rank 0 was meant to run a start";
  const Json summary = Json::parse(read_text(dir_ / "mpi" / "summary.json"));
  ASSERT_EQ(summary["starts"].size(), 4u);
  for (const Json& s : summary["starts"]) {
    const std::string start = std::to_string(s["start"].get<int>());
    EXPECT_FALSE(s["nlopt_result"].get<std::string>().empty());
    if (failed_starts.count(start) && start != "1") {
      EXPECT_TRUE(s["best"].is_null()) << s;
    }
  }
  // The result: the best feasible row of the history (the lowest objective, the earliest of
  // equal ones). In this study the starts rank 0 takes first (1 or 2) find feasible designs.
  const size_t objective = column_of(got[0], "objective"), feasible = column_of(got[0], "feasible");
  const std::vector<std::string>* best = nullptr;
  for (size_t i = 1; i < got.size(); ++i) {
    const auto& row = got[i];
    if (row[feasible] != "1") continue;
    if (!best || std::stod(row[objective]) < std::stod((*best)[objective])) best = &row;
  }
  if (!best) {  // the job still ends, saying so
    EXPECT_EQ(mpi.status, 1) << mpi.err;
    EXPECT_EQ(summary["status"], "infeasible");
    return;
  }
  EXPECT_EQ(mpi.status, 0) << mpi.err;
  EXPECT_EQ(summary["status"], "ok");
  const Json best_json = Json::parse(read_text(dir_ / "mpi" / "best.json"));
  EXPECT_EQ(std::to_string(best_json["start"].get<int>()), (*best)[0]);
  EXPECT_EQ(std::to_string(best_json["evaluation"].get<int>()), (*best)[1]);
}

}  // namespace
}  // namespace beamrail
