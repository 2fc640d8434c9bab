// Interrupted design studies resume to the uninterrupted result through the real command line
// (docs/study_files.md "--resume"): tables truncated to a shuffled subset of rows and a partial
// row, a table without a whole header, an optimization stopped half way, and a sweep killed
// (SIGKILL) again and again.
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/study_runs.hpp"

#ifndef BEAMRAIL_STUDIES_DIR
#error "BEAMRAIL_STUDIES_DIR must name the studies/ directory"
#endif

namespace beamrail {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using beamrail::testing::fields_of;
using beamrail::testing::lines_of;
using beamrail::testing::load_json;
using beamrail::testing::ProcessResult;
using beamrail::testing::raw_fields;
using beamrail::testing::read_table;
using beamrail::testing::read_text;
using beamrail::testing::SameText;
using beamrail::testing::save_text;
using beamrail::testing::Table;
using beamrail::testing::tube_grid;
using beamrail::testing::without_column;

const fs::path kStudies = BEAMRAIL_STUDIES_DIR;

class DesignStudyRuns : public testing::StudyRuns {};

// Whole rows only: every line has the header's column count and the file ends with a newline.
::testing::AssertionResult WholeRows(const std::string& text, size_t* rows) {
  bool whole = false;
  const std::vector<std::string> lines = lines_of(text, &whole);
  if (lines.empty() || !whole)
    return ::testing::AssertionFailure()
           << "empty or not ending with a newline: ..."
           << text.substr(text.size() - std::min<size_t>(80, text.size()));
  const size_t columns = raw_fields(lines[0]).size();
  for (size_t i = 1; i < lines.size(); ++i)
    if (raw_fields(lines[i]).size() != columns)
      return ::testing::AssertionFailure()
             << "line " << i + 1 << " has " << raw_fields(lines[i]).size() << " fields, not "
             << columns << ": " << lines[i];
  *rows = lines.size() - 1;
  return ::testing::AssertionSuccess();
}

// Indices 0..n-1, each once, in order.
::testing::AssertionResult IndicesInOrder(const fs::path& samples, size_t n) {
  const Table t = read_table(samples);
  if (t.rows.size() != n)
    return ::testing::AssertionFailure() << t.rows.size() << " rows, expected " << n;
  for (size_t i = 0; i < n; ++i)
    if (t.at(i, "index") != std::to_string(i))
      return ::testing::AssertionFailure() << "row " << i << " has index " << t.at(i, "index");
  return ::testing::AssertionSuccess();
}

TEST_F(DesignStudyRuns, SweepResumesFromAShuffledSubsetOfRowsAndAPartialRow) {
  const fs::path study = kStudies / "tube_cantilever_sweep.json";
  ASSERT_NO_FATAL_FAILURE(run_ok(study, "out"));
  const std::string reference = read_text(dir_ / "out" / "samples.csv");
  const std::vector<std::string> lines = lines_of(reference);
  const size_t n = lines.size() - 1;
  ASSERT_EQ(n, 45u);

  std::mt19937 rng(20240611);
  std::vector<size_t> kept, missing;
  for (size_t i = 1; i <= n; ++i) (rng() % 3 != 0 ? kept : missing).push_back(i);
  std::shuffle(kept.begin(), kept.end(), rng);
  ASSERT_FALSE(missing.empty());
  std::string text = lines[0] + "\n";
  for (size_t i : kept) text += lines[i] + "\n";
  const std::string& cut = lines[missing[missing.size() / 2]];
  text += cut.substr(0, cut.size() / 2);  // half a row, no newline
  save_text(dir_ / "out" / "samples.csv", text);
  fs::remove(dir_ / "out" / "summary.json");

  ASSERT_NO_FATAL_FAILURE(run_ok(study, "out", {"--resume"}));
  const std::string resumed = read_text(dir_ / "out" / "samples.csv");
  const Json summary = load_json(dir_ / "out" / "summary.json");
  std::printf(
      "sweep resume: kept %zu shuffled rows + half a row, %zu missing; evaluated_now %d, "
      "resumed_from_table %d\n",
      kept.size(), missing.size(), summary["evaluated_now"].get<int>(),
      summary["resumed_from_table"].get<int>());
  EXPECT_TRUE(SameText(without_column(reference, "wall_s"), without_column(resumed, "wall_s")));
  EXPECT_TRUE(IndicesInOrder(dir_ / "out" / "samples.csv", n));
  EXPECT_EQ(summary["evaluated_now"], missing.size());
  EXPECT_EQ(summary["resumed_from_table"], kept.size());
  EXPECT_EQ(summary["designs"], n);
}

// A run killed between creating its table and writing the header leaves an empty file (or, in
// principle, part of the header): --resume starts afresh instead of refusing the table.
TEST_F(DesignStudyRuns, ResumeFromATableWithoutAWholeHeaderStartsAfresh) {
  const struct {
    fs::path study;
    const char* table;
  } cases[] = {{kStudies / "tube_cantilever_sweep.json", "samples.csv"},
               {kStudies / "min_mass_rod.json", "history.csv"}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.table);
    ASSERT_NO_FATAL_FAILURE(run_ok(c.study, "ref"));
    const std::string reference = read_text(dir_ / "ref" / c.table);
    const std::string header = lines_of(reference).at(0);
    for (const std::string& left : {std::string(), header.substr(0, header.size() / 2)}) {
      fs::create_directories(dir_ / "out");
      save_text(dir_ / "out" / c.table, left);
      const ProcessResult r = run({"run", c.study.string(), "-o", "out", "--quiet", "--resume"});
      std::printf("%s left with %zu bytes: --resume %s %s", c.table, left.size(), r.how.c_str(),
                  r.err.c_str());
      ASSERT_TRUE(r.exited && r.status == 0) << r.how << "\n" << r.err;
      EXPECT_TRUE(SameText(without_column(reference, "wall_s"),
                           without_column(read_text(dir_ / "out" / c.table), "wall_s")));
      fs::remove_all(dir_ / "out");
    }
    std::printf("\n");
    fs::remove_all(dir_ / "ref");
  }
}

TEST_F(DesignStudyRuns, OptimizationResumesFromHalfItsHistory) {
  Json rod3 = load_json(kStudies / "min_mass_rod.json");
  rod3["study"]["algorithm"] = "LD_SLSQP";
  rod3["study"]["starts"] = 3;
  const fs::path files[] = {kStudies / "min_mass_rod.json", write_study("rod3.json", rod3)};
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.string());
    const bool single_start = file == files[0];
    ASSERT_NO_FATAL_FAILURE(run_ok(file, "ref"));
    const std::string reference = read_text(dir_ / "ref" / "history.csv");
    const Json ref_summary = load_json(dir_ / "ref" / "summary.json");
    const std::vector<std::string> lines = lines_of(reference);
    const size_t rows = lines.size() - 1, kept = rows / 2;
    ASSERT_GE(rows, 6u);

    fs::create_directories(dir_ / "out");
    // The record of the study that wrote the history, as an interrupted run leaves it.
    fs::copy_file(dir_ / "ref" / "resolved_study.json", dir_ / "out" / "resolved_study.json");
    std::string text;
    for (size_t i = 0; i <= kept; ++i) text += lines[i] + "\n";
    text += lines[kept + 1].substr(0, lines[kept + 1].size() / 2);
    save_text(dir_ / "out" / "history.csv", text);
    // Exact gradients: the derivatives of the kept rows' designs, as the interrupted run left
    // them (in the order the designs finished, which the reference's sorted table is not).
    if (fs::exists(dir_ / "ref" / "derivatives.csv")) {
      const std::vector<std::string> d = lines_of(read_text(dir_ / "ref" / "derivatives.csv"));
      std::string kept_derivatives = d[0] + "\n";
      for (size_t i = 1; i < d.size(); ++i)
        for (size_t r = 1; r <= kept; ++r)
          if (d[i].rfind(fields_of(lines[r], 2, 1) + ",", 0) == 0) {
            kept_derivatives += d[i] + "\n";
            break;
          }
      save_text(dir_ / "out" / "derivatives.csv", kept_derivatives);
    }
    ASSERT_NO_FATAL_FAILURE(run_ok(file, "out", {"--resume", "-j", "2"}));
    const Json summary = load_json(dir_ / "out" / "summary.json");
    const long simulated = summary["designs_simulated"],
               ref_simulated = ref_summary["designs_simulated"];
    std::printf(
        "%s: reference %zu rows, %ld designs simulated; resumed from %zu rows + half a row, "
        "%ld designs simulated\n",
        file.stem().c_str(), rows, ref_simulated, kept, simulated);
    EXPECT_TRUE(SameText(without_column(reference, "wall_s"),
                         without_column(read_text(dir_ / "out" / "history.csv"), "wall_s")));
    EXPECT_TRUE(
        SameText(read_text(dir_ / "ref" / "best.json"), read_text(dir_ / "out" / "best.json")));
    EXPECT_TRUE(SameText(read_text(dir_ / "ref" / "best_scene.json"),
                         read_text(dir_ / "out" / "best_scene.json")));
    if (fs::exists(dir_ / "ref" / "derivatives.csv")) {
      EXPECT_TRUE(SameText(read_text(dir_ / "ref" / "derivatives.csv"),
                           read_text(dir_ / "out" / "derivatives.csv")));
    }
    // Each row's design is simulated once at most; the kept rows are not simulated again.
    EXPECT_GT(simulated, 0);
    EXPECT_LT(simulated, ref_simulated);
    EXPECT_LE(simulated, static_cast<long>(rows - kept));
    if (single_start) {
      EXPECT_EQ(simulated, static_cast<long>(rows - kept));
    }
    fs::remove_all(dir_ / "ref");
    fs::remove_all(dir_ / "out");
  }
}

TEST_F(DesignStudyRuns, SweepKilledRepeatedlyResumesToTheUninterruptedResult) {
  // 900 designs of a segmented (slower) tube cantilever: about half a second on two threads; the
  // kill delays scale with the time the uninterrupted run takes.
  const fs::path study = write_study("big.json", tube_grid(kStudies, 30, 30, 8));
  ASSERT_NO_FATAL_FAILURE(run_ok(study, "ref", {"-j", "2"}));
  const std::string reference = read_text(dir_ / "ref" / "samples.csv");
  ASSERT_EQ(lines_of(reference).size(), 901u);
  const double reference_ms =
      1000 * load_json(dir_ / "ref" / "summary.json")["wall_seconds"].get<double>();
  std::printf("uninterrupted run: %.0f ms\n", reference_ms);

  const unsigned seed = std::random_device{}();
  std::mt19937 rng(seed);
  std::printf("kill delays from seed %u\n", seed);
  const fs::path samples = dir_ / "out" / "samples.csv";
  fs::create_directories(dir_ / "out");
  int killed = 0;
  for (int round = 0; round < 3; ++round) {
    // 5% to 30% of the uninterrupted run's time.
    const int delay_ms = static_cast<int>(reference_ms * (0.05 + 0.25 * (rng() % 1000) / 1000.0));
    std::vector<std::string> args{"run", study.string(), "-o", "out", "--quiet", "-j", "2"};
    if (round > 0) args.push_back("--resume");
    beamrail::testing::Process p(BEAMRAIL_EXECUTABLE, args, dir_, std::to_string(round));
    ASSERT_TRUE(p.started());
    // The delay counts from the moment the table exists.
    std::error_code ec;
    while (p.alive() && !(fs::exists(samples, ec) && fs::file_size(samples, ec) > 0))
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
    p.kill(SIGKILL);
    const ProcessResult r = p.wait(std::chrono::seconds(60));
    size_t rows = 0;
    ASSERT_TRUE(WholeRows(read_text(samples), &rows)) << "after round " << round;
    std::printf("round %d: SIGKILL after %d ms: %s, %zu whole rows\n", round, delay_ms,
                r.how.c_str(), rows);
    if (!r.exited) {
      EXPECT_EQ(r.signal, SIGKILL);
      ++killed;
    } else {
      EXPECT_EQ(r.status, 0) << r.err;  // finished before the kill
    }
  }
  EXPECT_GE(killed, 1) << "no run was interrupted: the test tested nothing";

  ASSERT_NO_FATAL_FAILURE(run_ok(study, "out", {"--resume", "-j", "2"}));
  const Json summary = load_json(dir_ / "out" / "summary.json");
  std::printf("final resume: evaluated_now %d, resumed_from_table %d\n",
              summary["evaluated_now"].get<int>(), summary["resumed_from_table"].get<int>());
  EXPECT_EQ(summary["evaluated_now"].get<int>() + summary["resumed_from_table"].get<int>(), 900);
  EXPECT_TRUE(
      SameText(without_column(reference, "wall_s"), without_column(read_text(samples), "wall_s")));
  EXPECT_TRUE(IndicesInOrder(samples, 900));
}

}  // namespace
}  // namespace beamrail
