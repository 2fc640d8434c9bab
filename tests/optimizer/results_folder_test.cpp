// The results folder through the real command line: a second run into a busy folder is refused,
// --resume refuses tables that another version of the study wrote, an interrupted run (SIGINT,
// SIGTERM) keeps what it computed and says so, time series reach the disk while a run lasts, write
// errors (file-size limit, full disk) fail the run with the file and the reason, the same folder
// problem gives the same exit status for every kind of study, and absurd thread counts neither
// crash nor start thousands of threads.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/file.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/study_runs.hpp"

#ifndef BEAMRAIL_EXECUTABLE
#error "BEAMRAIL_EXECUTABLE must name the beamrail binary"
#endif
#ifndef BEAMRAIL_STUDIES_DIR
#error "BEAMRAIL_STUDIES_DIR must name the studies/ directory"
#endif

namespace beamrail {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using testing::Limits;
using testing::lines_of;
using testing::load_json;
using testing::Process;
using testing::ProcessResult;
using testing::read_text;
using testing::save_text;

const fs::path kStudies = BEAMRAIL_STUDIES_DIR;

size_t count_fields(const std::string& line) {
  size_t n = 1;
  bool quoted = false;
  for (char c : line) {
    if (c == '"') quoted = !quoted;
    n += c == ',' && !quoted;
  }
  return n;
}

// A table of whole rows, each with the header's number of fields; *rows receives their number.
::testing::AssertionResult WholeRows(const fs::path& path, size_t* rows) {
  const std::string text = read_text(path);
  bool whole = false;
  const std::vector<std::string> lines = lines_of(text, &whole);
  if (lines.empty() || !whole)
    return ::testing::AssertionFailure()
           << path << " is empty or does not end with a newline: ..."
           << text.substr(text.size() - std::min<size_t>(80, text.size()));
  for (size_t i = 1; i < lines.size(); ++i)
    if (count_fields(lines[i]) != count_fields(lines[0]))
      return ::testing::AssertionFailure()
             << path << " line " << i + 1 << " has " << count_fields(lines[i]) << " fields, not "
             << count_fields(lines[0]) << ": " << lines[i];
  *rows = lines.size() - 1;
  return ::testing::AssertionSuccess();
}

// The first fields (sweep indices) of a table's rows.
std::vector<long> first_fields(const fs::path& path) {
  std::vector<long> out;
  const std::vector<std::string> lines = lines_of(read_text(path));
  for (size_t i = 1; i < lines.size(); ++i) out.push_back(std::stol(lines[i]));
  return out;
}

size_t data_rows(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return 0;
  const size_t lines = lines_of(read_text(path)).size();
  return lines > 0 ? lines - 1 : 0;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Waits (polling) until done() or the process ends or `limit` passes; true when done().
bool wait_until(Process& p, const std::function<bool()>& done, std::chrono::seconds limit) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < deadline) {
    if (done()) return true;
    if (!p.alive()) return done();
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return done();
}

// A steel cantilever of 10 segments with a 1 kg tip body under a 1 N tip load; its transient at
// rtol 1e-8 delivers some tens of output rows a second on this machine.
Json cantilever_study(const std::string& name) {
  Json s = Json::parse(R"({
    "scene": {
      "materials": {"steel": {"E": 2.1e11, "G": 8.1e10, "density": 7850}},
      "sections": {"sq10": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
      "bodies": [{"name": "tip", "mass": 1.0, "inertia": [0.001, 0.001, 0.001],
                  "position": [1, 0, 0]}],
      "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
                 "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq10",
                 "segments": 10}],
      "loads": [{"type": "force", "body": "tip", "value": [0, -1, 0]}]
    },
    "analyses": [{"type": "transient", "t_end": 0.01, "output_step": 0.001,
                  "integrator": {"rtol": 1e-8, "atol": 1e-11}}],
    "responses": {"peak": {"quantity": "peak_displacement", "body": "tip",
                           "direction": [0, 1, 0]}}
  })");
  s["name"] = name;
  return s;
}

// 40 designs of that cantilever, each a transient of t_end seconds (0.01 s: some hundredths of a
// second of computing).
Json slow_sweep(double t_end = 0.01) {
  Json s = cantilever_study("slow_sweep");
  s["analyses"][0]["t_end"] = t_end;
  s["study"] = Json::parse(R"({"type": "sweep", "variables": [{"name": "load",
      "pointer": "/scene/loads/0/value/1", "lower": -2, "upper": -1, "count": 40}]})");
  return s;
}

// A transient that runs for minutes (1000 s of motion at output steps of 0.01 s).
Json long_transient() {
  Json s = cantilever_study("long_transient");
  s["analyses"][0]["t_end"] = 1000.0;
  s["analyses"][0]["output_step"] = 0.01;
  s["analyses"][0]["max_seconds"] = 120.0;  // a guard should the run not be stopped
  return s;
}

class ResultsFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "beamrail_results_XXXXXX").string();
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

  ProcessResult run(const std::vector<std::string>& args, Limits limits = {}) {
    return testing::run_process(BEAMRAIL_EXECUTABLE, args, dir_, std::chrono::seconds(120), limits);
  }

  // `beamrail run study -o out --quiet [extra]`, which must exit 0.
  void run_ok(const fs::path& study, const std::string& out,
              const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args{"run", study.string(), "-o", out, "--quiet"};
    args.insert(args.end(), extra.begin(), extra.end());
    const ProcessResult r = run(args);
    ASSERT_TRUE(r.exited && r.status == 0)
        << "beamrail run " << study.string() << ": " << r.how << "\n"
        << r.err;
  }

  fs::path dir_;
};

// --- A busy folder -------------------------------------------------------------------------------

// While a run holds its folder, any other run into it is refused (exit status 1, nothing written):
// a sweep, an optimization, a work-precision study and a single run alike.
TEST_F(ResultsFolder, ARunIntoAFolderHeldByAnotherRunIsRefused) {
  fs::create_directories(dir_ / "out");
  // Holds the lock as a running beamrail would.
  const int fd = ::open((dir_ / "out" / ".beamrail.lock").c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  for (const std::string study : {"tube_cantilever_sweep.json", "min_mass_rod.json",
                                  "work_precision_reference.json", "bending_tip_load.json"}) {
    SCOPED_TRACE(study);
    const ProcessResult r = run({"run", (kStudies / study).string(), "-o", "out", "--quiet"});
    std::printf("%s: %s: %s", study.c_str(), r.how.c_str(), r.err.c_str());
    EXPECT_TRUE(r.exited && r.status == 1) << r.how;
    EXPECT_TRUE(
        contains(r.err, "beamrail: the output folder out is in use by another beamrail run"))
        << r.err;
    EXPECT_TRUE(contains(r.err, "choose another folder with -o")) << r.err;
    for (const char* file : {"summary.json", "samples.csv", "history.csv", "work_precision.csv",
                             "timeseries.csv", "resolved_study.json"})
      EXPECT_FALSE(fs::exists(dir_ / "out" / file)) << file;
  }
  ::close(fd);
}

// Two real runs of a sweep into one folder: the second is refused while the first runs; the
// first one's table holds whole rows, each design once. (The first run's designs take about a
// quarter of a second each; it is stopped by SIGINT once the second was refused.)
TEST_F(ResultsFolder, TheSecondOfTwoConcurrentSweepsIsRefused) {
  const fs::path study = write_study("sweep.json", slow_sweep(0.05));
  const fs::path samples = dir_ / "out" / "samples.csv";
  Process first(BEAMRAIL_EXECUTABLE, {"run", study.string(), "-o", "out", "--quiet"}, dir_, "1");
  ASSERT_TRUE(wait_until(
      first, [&] { return data_rows(samples) >= 1; }, std::chrono::seconds(60)))
      << "the first run wrote no row";
  ASSERT_TRUE(first.alive()) << "the first run ended before the second started";
  const ProcessResult second = run({"run", study.string(), "-o", "out", "--quiet"});
  std::printf("second run: %s: %s", second.how.c_str(), second.err.c_str());
  EXPECT_TRUE(second.exited && second.status == 1) << second.how;
  EXPECT_TRUE(contains(second.err, "is in use by another beamrail run")) << second.err;

  first.kill(SIGINT);
  const ProcessResult r = first.wait(std::chrono::seconds(120));
  EXPECT_TRUE(r.exited && (r.status == 130 || r.status == 0)) << r.how << "\n" << r.err;
  size_t rows = 0;
  ASSERT_TRUE(WholeRows(samples, &rows));
  EXPECT_GE(rows, 1u);
  const std::vector<long> indices = first_fields(samples);
  EXPECT_EQ(std::set<long>(indices.begin(), indices.end()).size(), indices.size());
}

// --- --resume after editing the study -----------------------------------------------------------

// Each edit changes what the table holds (bounds, count, sampling seed, a number of the scene file
// with the same columns): --resume must refuse (exit status 2), name the first difference and
// leave the tables as they were. Edits that change no result (the description, -j) resume.
TEST_F(ResultsFolder, ResumeRefusesTablesOfAnotherVersionOfTheStudy) {
  fs::create_directories(dir_ / "scenes");
  Json sweep = load_json(kStudies / "tube_cantilever_sweep.json");
  std::ofstream(dir_ / "scenes" / "tube.json") << sweep["scene"].dump(2);
  sweep["scene"] = "scenes/tube.json";
  sweep["study"]["variables"][0]["count"] = 3;
  sweep["study"]["variables"][1]["values"] = Json{0.002, 0.004};
  const fs::path study = write_study("sweep.json", sweep);
  ASSERT_NO_FATAL_FAILURE(run_ok(study, "out"));
  const std::string table = read_text(dir_ / "out" / "samples.csv");
  ASSERT_EQ(lines_of(table).size(), 7u);

  struct Edit {
    std::string what, pointer;
    std::function<void(Json&)> apply;
  };
  const std::vector<Edit> edits = {
      {"new upper bound", "/study/variables/0/upper",
       [](Json& s) { s["study"]["variables"][0]["upper"] = 0.07; }},
      {"new count", "/study/variables/0/count",
       [](Json& s) { s["study"]["variables"][0]["count"] = 4; }},
      {"new wall values", "/study/variables/1/values/1",
       [](Json& s) { s["study"]["variables"][1]["values"][1] = 0.005; }},
      {"new analysis option", "/analyses/1/modes", [](Json& s) { s["analyses"][1]["modes"] = 2; }},
  };
  for (const Edit& e : edits) {
    SCOPED_TRACE(e.what);
    Json edited = sweep;
    e.apply(edited);
    const fs::path file = write_study("edited.json", edited);
    const ProcessResult r = run({"run", file.string(), "-o", "out", "--quiet", "--resume"});
    std::printf("%s: %s: %s", e.what.c_str(), r.how.c_str(), r.err.c_str());
    EXPECT_TRUE(r.exited && r.status == 2) << r.how;
    EXPECT_TRUE(contains(r.err, "cannot resume")) << r.err;
    EXPECT_TRUE(contains(r.err, "first difference at " + e.pointer)) << r.err;
    EXPECT_TRUE(contains(r.err, "run without --resume")) << r.err;
    EXPECT_EQ(read_text(dir_ / "out" / "samples.csv"), table);
  }

  // The scene file changed under the same study file: same columns, other designs.
  const std::string scene_text = read_text(dir_ / "scenes" / "tube.json");
  Json scene = Json::parse(scene_text);
  scene["bodies"][0]["mass"] = 4.0;
  std::ofstream(dir_ / "scenes" / "tube.json") << scene.dump(2);
  const ProcessResult r = run({"run", study.string(), "-o", "out", "--quiet", "--resume"});
  std::printf("scene file edited: %s: %s", r.how.c_str(), r.err.c_str());
  EXPECT_TRUE(r.exited && r.status == 2) << r.how;
  EXPECT_TRUE(contains(r.err, "first difference at /scene/bodies/0/mass")) << r.err;
  EXPECT_EQ(read_text(dir_ / "out" / "samples.csv"), table);
  std::ofstream(dir_ / "scenes" / "tube.json") << scene_text;

  // A new description and another -j change no result: the table resumes, nothing is evaluated.
  Json described = sweep;
  described["description"] = "the same study, described anew";
  ASSERT_NO_FATAL_FAILURE(
      run_ok(write_study("described.json", described), "out", {"--resume", "-j", "1"}));
  const Json summary = load_json(dir_ / "out" / "summary.json");
  EXPECT_EQ(summary["evaluated_now"], 0);
  EXPECT_EQ(summary["resumed_from_table"], 6);
}

// An optimization's history is refused the same way (its best.json would not match it).
TEST_F(ResultsFolder, ResumeRefusesTheHistoryOfAnotherOptimization) {
  Json rod = load_json(kStudies / "min_mass_rod.json");
  rod["study"]["max_evaluations"] = 10;
  const fs::path study = write_study("rod.json", rod);
  ASSERT_NO_FATAL_FAILURE(run_ok(study, "out"));
  const std::string history = read_text(dir_ / "out" / "history.csv");
  const std::string best = read_text(dir_ / "out" / "best.json");
  rod["study"]["variables"][0]["lower"] = 0.01;
  const ProcessResult r =
      run({"run", write_study("rod2.json", rod).string(), "-o", "out", "--quiet", "--resume"});
  std::printf("%s: %s", r.how.c_str(), r.err.c_str());
  EXPECT_TRUE(r.exited && r.status == 2) << r.how;
  EXPECT_TRUE(contains(r.err, "first difference at /study/variables/0/lower")) << r.err;
  EXPECT_EQ(read_text(dir_ / "out" / "history.csv"), history);
  EXPECT_EQ(read_text(dir_ / "out" / "best.json"), best);
}

// --- Interruption
// ---------------------------------------------------------------------------------

// SIGINT stops a sweep cleanly: exit status 130, a message saying what was kept and how to go on,
// summary.json says "interrupted", the rows computed are in the table (whole, each design once),
// and --resume completes it.
TEST_F(ResultsFolder, AnInterruptedSweepKeepsItsRowsAndResumes) {
  const fs::path study = write_study("sweep.json", slow_sweep());
  const fs::path samples = dir_ / "out" / "samples.csv";
  Process p(BEAMRAIL_EXECUTABLE, {"run", study.string(), "-o", "out", "--quiet", "-j", "2"}, dir_);
  ASSERT_TRUE(wait_until(
      p, [&] { return data_rows(samples) >= 3; }, std::chrono::seconds(60)));
  p.kill(SIGINT);
  const ProcessResult r = p.wait(std::chrono::seconds(60));
  std::printf("%s: %s", r.how.c_str(), r.err.c_str());
  ASSERT_TRUE(r.exited) << r.how;
  ASSERT_EQ(r.status, 130) << r.err;
  size_t rows = 0;
  ASSERT_TRUE(WholeRows(samples, &rows));
  EXPECT_GE(rows, 3u);
  EXPECT_LT(rows, 40u);
  const Json summary = load_json(dir_ / "out" / "summary.json");
  EXPECT_EQ(summary["status"], "interrupted");
  EXPECT_EQ(summary["designs_in_table"], rows);
  EXPECT_TRUE(contains(r.err, "interrupted by SIGINT")) << r.err;
  EXPECT_TRUE(contains(r.err, std::to_string(rows) + " of 40 designs are in")) << r.err;
  EXPECT_TRUE(contains(r.err, "--resume")) << r.err;
  const std::vector<long> kept = first_fields(samples);
  EXPECT_EQ(std::set<long>(kept.begin(), kept.end()).size(), rows);

  ASSERT_NO_FATAL_FAILURE(run_ok(study, "out", {"--resume", "-j", "2"}));
  const Json resumed = load_json(dir_ / "out" / "summary.json");
  EXPECT_EQ(resumed["status"], "ok");
  EXPECT_EQ(resumed["resumed_from_table"], rows);
  EXPECT_EQ(resumed["evaluated_now"], 40 - rows);
  std::vector<long> all = first_fields(samples);
  ASSERT_EQ(all.size(), 40u);
  for (long i = 0; i < 40; ++i) EXPECT_EQ(all[i], i);
}

// A single run re-run into the folder of a complete run, then stopped by SIGTERM: the folder must
// not show the old "ok" beside the new partial time series. summary.json says "interrupted" (from
// the start of the run it says "running"), the time series holds whole rows up to the stop, the
// exit status is 143. While the run lasts, its rows reach the disk at least every second.
TEST_F(ResultsFolder, AnInterruptedSingleRunMarksTheFolderAndKeepsItsRows) {
  Json quick = long_transient();
  quick["analyses"][0]["t_end"] = 0.02;
  ASSERT_NO_FATAL_FAILURE(run_ok(write_study("quick.json", quick), "out"));
  ASSERT_EQ(load_json(dir_ / "out" / "summary.json")["status"], "ok");

  const fs::path study = write_study("long.json", long_transient());
  const fs::path partial = dir_ / "out" / "timeseries.csv.partial";
  Process p(BEAMRAIL_EXECUTABLE, {"run", study.string(), "-o", "out", "--quiet"}, dir_);
  // The run's rows appear while it runs (a row is ~120 bytes: buffering until 64 KiB or the end
  // would show none for tens of seconds).
  const bool rows_seen = wait_until(
      p, [&] { return data_rows(partial) >= 2; }, std::chrono::seconds(8));
  EXPECT_TRUE(rows_seen) << "no time series row reached the disk within 8 s";
  EXPECT_EQ(load_json(dir_ / "out" / "summary.json")["status"], "running");
  p.kill(SIGTERM);
  const ProcessResult r = p.wait(std::chrono::seconds(60));
  std::printf("%s: %s", r.how.c_str(), r.err.c_str());
  ASSERT_TRUE(r.exited) << r.how;
  EXPECT_EQ(r.status, 143) << r.err;
  EXPECT_TRUE(contains(r.err, "interrupted by SIGTERM")) << r.err;
  const Json summary = load_json(dir_ / "out" / "summary.json");
  EXPECT_EQ(summary["status"], "interrupted");
  EXPECT_EQ(summary["analyses"][0]["status"], "interrupted");
  size_t rows = 0;
  ASSERT_TRUE(WholeRows(dir_ / "out" / "timeseries.csv", &rows));
  EXPECT_FALSE(fs::exists(partial));
  EXPECT_GE(rows, 2u);
  const double t_last = std::stod(lines_of(read_text(dir_ / "out" / "timeseries.csv")).back());
  EXPECT_NEAR(t_last, summary["analyses"][0]["t_reached"].get<double>(), 0.011);
  EXPECT_LT(t_last, 1000.0);
}

// A run killed outright (SIGKILL: no handler runs) still leaves the rows of the last second on
// the disk, whole but perhaps for the last line, and summary.json saying the folder is
// incomplete.
TEST_F(ResultsFolder, AKilledSingleRunLeavesItsRowsOnDisk) {
  const fs::path study = write_study("long.json", long_transient());
  const fs::path partial = dir_ / "out" / "timeseries.csv.partial";
  Process p(BEAMRAIL_EXECUTABLE, {"run", study.string(), "-o", "out", "--quiet"}, dir_);
  const bool rows_seen = wait_until(
      p, [&] { return data_rows(partial) >= 2; }, std::chrono::seconds(8));
  p.kill(SIGKILL);
  p.wait(std::chrono::seconds(60));
  EXPECT_TRUE(rows_seen) << "no time series row reached the disk within 8 s";
  // The kill can stop the write of the one row that crosses a page of the file between its two
  // pages (write_rows; it did once in CI when rows went 64 KiB at a time): an unfinished last
  // line is dropped, as --resume drops one, and every row before it is whole.
  std::string text = read_text(partial);
  if (!text.empty() && text.back() != '\n') text.erase(text.rfind('\n') + 1);
  save_text(dir_ / "whole_rows.csv", text);
  size_t rows = 0;
  ASSERT_TRUE(WholeRows(dir_ / "whole_rows.csv", &rows));
  EXPECT_GE(rows, 2u);
  EXPECT_EQ(load_json(dir_ / "out" / "summary.json")["status"], "running");
}

// --- Write errors --------------------------------------------------------------------------------

// A file-size limit (RLIMIT_FSIZE; SIGXFSZ ignored, so writes fail with EFBIG) cuts every kind of
// table: the run fails (exit status 1) naming the file and the system's reason, and the table ends
// with a whole row.
TEST_F(ResultsFolder, AWriteErrorFailsTheRunWithTheFileAndTheReason) {
  Json single = long_transient();
  single["scene"]["beams"][0]["segments"] = 0;  // fast
  single["analyses"][0]["t_end"] = 10.0;        // 1,000 rows, ~120 kB
  Json sweep = load_json(kStudies / "tube_cantilever_sweep.json");
  sweep["study"]["variables"][0]["count"] = 200;  // 1,000 rows, ~150 kB
  Json wp = load_json(kStudies / "work_precision_reference.json");
  wp["scene"]["beams"][0]["segments"] = 2;
  wp["analyses"][0]["t_end"] = 0.002;
  wp["study"]["methods"] = Json::parse(R"([{"method": "erk"}])");
  Json rtols = Json::array();
  for (int i = 0; i < 300; ++i) rtols.push_back(1e-3 * (1.0 + 0.01 * i));  // 300 rows, ~30 kB
  wp["study"]["rtols"] = rtols;
  const struct {
    const char* name;
    Json study;
    const char* table;
  } cases[] = {{"single", single, "timeseries.csv"},
               {"sweep", sweep, "samples.csv"},
               {"work_precision", wp, "work_precision.csv"}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path study = write_study(std::string(c.name) + ".json", c.study);
    const std::string out = std::string("out_") + c.name;
    const ProcessResult r =
        run({"run", study.string(), "-o", out, "--quiet"}, Limits{.file_size = 16384});
    std::printf("%s: %s: %s", c.name, r.how.c_str(), r.err.c_str());
    ASSERT_TRUE(r.exited) << r.how;
    EXPECT_EQ(r.status, 1);
    const std::string expected =
        "cannot write " + out + "/" + c.table + ": " + std::strerror(EFBIG);
    EXPECT_TRUE(contains(r.err, expected)) << r.err;
    size_t rows = 0;
    EXPECT_TRUE(WholeRows(dir_ / out / c.table, &rows));
    EXPECT_LE(fs::file_size(dir_ / out / c.table), 16384u);
    const Json summary = load_json(dir_ / out / "summary.json");
    EXPECT_EQ(summary["status"], "failed");
    EXPECT_TRUE(contains(summary["message"].get<std::string>(), expected)) << summary["message"];
  }
}

// A full disk, by way of /dev/full (writes to it fail with ENOSPC): wherever it strikes, the
// first file a run writes (its "running" summary) or its first table, every kind of study fails
// the same way, exit status 1, naming the file and the reason.
TEST_F(ResultsFolder, AFullDiskFailsEveryKindOfStudyTheSameWay) {
  const struct {
    const char* study;
    const char* table;    // the first table it writes
    const char* written;  // where it is written (a staged table: beside it)
  } cases[] = {
      {"tube_cantilever_sweep.json", "samples.csv", "samples.csv"},
      {"min_mass_rod.json", "history.csv", "history.csv"},
      {"work_precision_reference.json", "work_precision.csv", "work_precision.csv.partial"},
      {"bending_tip_period.json", "timeseries.csv", "timeseries.csv.partial"}};
  for (const auto& c : cases) {
    for (const bool summary : {true, false}) {
      SCOPED_TRACE(std::string(c.study) + (summary ? ", summary.json" : ", the first table"));
      fs::remove_all(dir_ / "out");
      fs::create_directories(dir_ / "out");
      fs::create_symlink("/dev/full", dir_ / "out" / (summary ? "summary.json.tmp" : c.written));
      Json s = load_json(kStudies / c.study);
      if (std::string(c.study) == "work_precision_reference.json") {
        s["scene"]["beams"][0]["segments"] = 2;
        s["analyses"][0]["t_end"] = 0.002;
      }
      const fs::path file = write_study(c.study, s);
      const ProcessResult r = run({"run", file.string(), "-o", "out", "--quiet"});
      std::printf("%s: %s: %s", c.study, r.how.c_str(), r.err.c_str());
      EXPECT_TRUE(r.exited && r.status == 1) << r.how;
      EXPECT_TRUE(contains(r.err, "cannot write out/" +
                                      std::string(summary ? "summary.json" : c.table) + ": " +
                                      std::strerror(ENOSPC)))
          << r.err;
    }
  }
}

// A table that cannot be created (a folder of its name is in the way) is the same condition for
// every kind of study: exit status 1 with the path and the reason (sweeps and optimizations used
// to say 2, "bad input").
TEST_F(ResultsFolder, ATableThatCannotBeWrittenIsExitStatus1ForEveryKindOfStudy) {
  const struct {
    const char* study;
    const char* table;
  } cases[] = {{"tube_cantilever_sweep.json", "samples.csv"},
               {"min_mass_rod.json", "history.csv"},
               {"work_precision_reference.json", "work_precision.csv"},
               {"bending_tip_period.json", "timeseries.csv"}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.study);
    fs::remove_all(dir_ / "out");
    fs::create_directories(dir_ / "out" / c.table);
    Json s = load_json(kStudies / c.study);
    if (std::string(c.study) == "work_precision_reference.json") {
      s["scene"]["beams"][0]["segments"] = 2;
      s["analyses"][0]["t_end"] = 0.002;
    }
    const fs::path file = write_study(c.study, s);
    const ProcessResult r = run({"run", file.string(), "-o", "out", "--quiet"});
    std::printf("%s: %s: %s", c.study, r.how.c_str(), r.err.c_str());
    EXPECT_TRUE(r.exited && r.status == 1) << r.how;
    EXPECT_TRUE(
        contains(r.err, std::string("cannot write out/") + c.table + ": " + std::strerror(EISDIR)))
        << r.err;
  }
}

// --- Threads
// --------------------------------------------------------------------------------------

// -j beyond 1024 is refused as bad input; a large -j is cut to the designs a batch can evaluate
// at once. Under a 1 GiB address-space limit, a thousand threads (8 MiB of stack each) cannot even
// start: the runs pass only if they start no more threads than they need.
TEST_F(ResultsFolder, ThreadsAreCappedByTheWorkAndAbsurdCountsRefused) {
  for (const char* n : {"100000", "32768", "1025"}) {
    const ProcessResult r = run({"run", (kStudies / "tube_cantilever_sweep.json").string(), "-o",
                                 "out", "--quiet", "-j", n});
    std::printf("-j %s: %s: %s", n, r.how.c_str(), r.err.c_str());
    EXPECT_TRUE(r.exited && r.status == 2) << r.how;
    EXPECT_TRUE(contains(r.err, std::string("beamrail: -j ") + n + ": at most 1024 threads"))
        << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "out"));
  }

  Json sweep = load_json(kStudies / "tube_cantilever_sweep.json");
  sweep["study"]["variables"][0]["count"] = 3;
  sweep["study"]["variables"][1]["values"] = Json{0.002};
  Json rod = load_json(kStudies / "min_mass_rod.json");
  rod["study"]["algorithm"] = "LD_SLSQP";  // gradients: 3 designs at once for 1 variable
  rod["study"]["gradient"] = "fd";         // (by central differences)
  rod["study"]["max_evaluations"] = 5;
#if defined(__SANITIZE_ADDRESS__)
  // AddressSanitizer reserves terabytes of address space: no limit then (the thread count in
  // summary.json is still checked).
  const Limits gib{};
#else
  const Limits gib{.address_space = 1L << 30};
#endif
  for (const auto& [name, study] : {std::pair{"sweep", sweep}, std::pair{"rod", rod}}) {
    SCOPED_TRACE(name);
    const fs::path file = write_study(std::string(name) + ".json", study);
    const std::string out = std::string("out_") + name;
    const ProcessResult r = run({"run", file.string(), "-o", out, "--quiet", "-j", "1000"}, gib);
    std::printf("%s -j 1000: %s: %s", name, r.how.c_str(), r.err.c_str());
    ASSERT_TRUE(r.exited && r.status == 0) << r.how << "\n" << r.err;
    EXPECT_EQ(load_json(dir_ / out / "summary.json")["threads"], 3);
  }
}

}  // namespace
}  // namespace beamrail
