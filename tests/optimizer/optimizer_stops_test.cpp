// How an optimization ends, through the real command line: NLopt combinations it cannot run are
// bad input when the study is read (not a start point reported as the optimum), wrappers get the
// local optimizers they need (MLSL inside an augmented Lagrangian, LN_AUGLAG itself), an NLopt
// failure fails the study, ROUNDOFF_LIMITED is reported as a warning, a start stops when it has
// evaluated max_evaluations designs (not NLopt calls), and each start reports why it stopped and
// its best design.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
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
#ifndef BEAMRAIL_STUDIES_DIR
#error "BEAMRAIL_STUDIES_DIR must name the studies/ directory"
#endif

namespace beamrail {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using testing::ProcessResult;
using testing::read_text;

const fs::path kStudies = BEAMRAIL_STUDIES_DIR;

Json load_json(const fs::path& path) { return Json::parse(read_text(path)); }

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  size_t start = 0;
  for (size_t i = 0; i < text.size(); ++i)
    if (text[i] == '\n') lines.push_back(text.substr(start, i - start)), start = i + 1;
  return lines;
}

// The rows of history.csv per start (its first column); the tables here have no quoted fields
// before the message column.
std::map<int, int> rows_per_start(const std::string& history) {
  std::map<int, int> rows;
  const std::vector<std::string> lines = lines_of(history);
  for (size_t i = 1; i < lines.size(); ++i)
    ++rows[std::stoi(lines[i].substr(0, lines[i].find(',')))];
  return rows;
}

// The lightest rod keeping f1 >= 20 Hz (studies/min_mass_rod.json): the optimum is d* = 48.20 mm
// on the constraint, objective (mass) 16.32 kg.
Json rod(const std::string& algorithm, int max_evaluations) {
  Json s = load_json(kStudies / "min_mass_rod.json");
  s["study"]["algorithm"] = algorithm;
  s["study"]["max_evaluations"] = max_evaluations;
  return s;
}

class OptimizerStops : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "beamrail_stops_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  ProcessResult run(const std::string& name, const Json& study,
                    const std::string& command = "run") {
    std::ofstream(dir_ / name) << study.dump(2);
    std::vector<std::string> args{command, name};
    if (command == "run") args.insert(args.end(), {"-o", "out", "--quiet"});
    return testing::run_process(BEAMRAIL_EXECUTABLE, args, dir_, std::chrono::seconds(60));
  }
  fs::path dir_;
};

// MLSL takes no constraints: it runs inside LN_AUGLAG, and needs a local optimizer of its own
// there. Without one, NLopt stopped every start after its first evaluation (INVALID_ARGS, or a
// crash for GN_MLSL_LDS) and the study reported the start point as the optimum.
TEST_F(OptimizerStops, MlslWithConstraintsRunsInsideAnAugmentedLagrangian) {
  for (const std::string algorithm : {"G_MLSL_LDS", "GN_MLSL_LDS"}) {
    SCOPED_TRACE(algorithm);
    Json s = rod(algorithm, 60);
    s["study"]["starts"] = 2;
    s["study"]["variables"][0]["initial"] = 0.09;  // 51.9 kg
    const ProcessResult r = run("mlsl.json", s);
    ASSERT_TRUE(r.exited && r.status == 0) << r.how << "\n" << r.err;
    const Json summary = load_json(dir_ / "out" / "summary.json");
    const Json best = load_json(dir_ / "out" / "best.json");
    std::printf("%s: %s, %s, best d = %.6g, objective %.6g\n", algorithm.c_str(),
                summary["optimizer"].get<std::string>().c_str(), summary["starts"].dump().c_str(),
                best["variables"]["d"].get<double>(), best["objective"].get<double>());
    EXPECT_EQ(summary["status"], "ok");
    EXPECT_EQ(summary["optimizer"], "LN_AUGLAG(" + algorithm + "(LN_COBYLA))");
    for (const Json& start : summary["starts"]) {
      EXPECT_GT(start["designs"].get<int>(), 10) << start.dump();
      const std::string result = start["nlopt_result"];
      EXPECT_TRUE(result == "MAXEVAL_REACHED" || result == "XTOL_REACHED" ||
                  result == "FTOL_REACHED" || result == "SUCCESS")
          << result;
    }
    // Far better than the initial point (d = 90 mm, 51.9 kg; the optimum is 16.32 kg) and
    // feasible.
    EXPECT_LT(best["objective"].get<double>(), 25.0);
    EXPECT_GE(best["responses"]["f1"].get<double>(), 20.0 * (1 - 1e-9));
    fs::remove_all(dir_ / "out");
  }
}

// An AUGLAG variant named as the algorithm gets the default local optimizer (NLopt's own default
// crashed the process), with and without constraints.
TEST_F(OptimizerStops, AugmentedLagrangiansNamedAsTheAlgorithmRun) {
  // (LD_AUGLAG with the constraint works too, but needs a few seconds.)
  const std::pair<std::string, bool> cases[] = {{"LN_AUGLAG", true},
                                                {"LN_AUGLAG", false},
                                                {"LN_AUGLAG_EQ", true},
                                                {"LN_AUGLAG_EQ", false},
                                                {"LD_AUGLAG", false}};
  for (const auto& [algorithm, constrained] : cases) {
    SCOPED_TRACE(algorithm + (constrained ? " with a constraint" : " without constraints"));
    Json s = rod(algorithm, 100);
    if (!constrained) {
      s["study"].erase("constraints");
      s["study"]["objective"] = Json::parse(R"({"target": {"f1": 25.0}})");
    }
    const ProcessResult r = run("auglag.json", s);
    std::printf("%s%s: %s %s", algorithm.c_str(), constrained ? " constrained" : "", r.how.c_str(),
                r.out.c_str());
    ASSERT_TRUE(r.exited && r.status == 0) << r.how << "\n" << r.err;
    const Json summary = load_json(dir_ / "out" / "summary.json");
    EXPECT_EQ(summary["status"], "ok");
    EXPECT_GT(summary["designs_in_history"].get<int>(), 10);
    // Better than the initial point (17.41 kg; f1 = 48 Hz, 23 Hz off the target).
    EXPECT_LT(load_json(dir_ / "out" / "best.json")["objective"].get<double>(),
              constrained ? 17.0 : 1e-3);
    fs::remove_all(dir_ / "out");
  }
}

// What NLopt refuses to run is refused when the study is read, by `check` and `run` alike: exit
// status 2, one line "file:/json/pointer: message", nothing written.
TEST_F(OptimizerStops, CombinationsNloptCannotRunAreBadInput) {
  Json local_wrapper = rod("AUGLAG", 40);
  local_wrapper["study"]["local_algorithm"] = "LN_AUGLAG";
  const struct {
    const char* what;
    Json study;
    const char* where;
    const char* message;
  } cases[] = {
      {"an algorithm this NLopt lacks", rod("GD_STOGO", 40),
       "rod.json:/study/algorithm: NLopt cannot run LD_AUGLAG(GD_STOGO) with 1 constraint",
       "INVALID_ARGS"},
      {"NEWUOA in one dimension", rod("LN_NEWUOA_BOUND", 40),
       "rod.json:/study/algorithm: NLopt cannot run LN_AUGLAG(LN_NEWUOA_BOUND) with 1 constraint",
       "INVALID_ARGS"},
      {"a wrapper as the local optimizer", local_wrapper,
       "rod.json:/study/local_algorithm: ", "\"LN_AUGLAG\" runs a local optimizer itself"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    for (const std::string command : {"check", "run"}) {
      const ProcessResult r = run("rod.json", c.study, command);
      std::printf("%s, %s: %s: %s", c.what, command.c_str(), r.how.c_str(), r.err.c_str());
      EXPECT_TRUE(r.exited && r.status == 2) << r.how;
      EXPECT_EQ(r.err.rfind(c.where, 0), 0u) << r.err;
      EXPECT_TRUE(contains(r.err, c.message)) << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
      EXPECT_FALSE(fs::exists(dir_ / "out"));
    }
  }
}

// LD_LBFGS inside LD_AUGLAG, given central differences over 45 % of the variable's range (a
// gradient it cannot follow), ends with NLopt's FAILURE: the study fails (exit status 1,
// summary.json "failed" with NLopt's result), and no best.json claims an optimum.
TEST_F(OptimizerStops, AnNloptFailureFailsTheStudy) {
  Json s = rod("LD_LBFGS", 200);
  s["study"]["gradient"] = "fd";
  s["study"]["gradient_step"] = 0.45;
  const ProcessResult r = run("lbfgs.json", s);
  std::printf("%s: %s", r.how.c_str(), r.err.c_str());
  ASSERT_TRUE(r.exited) << r.how;
  const Json summary = load_json(dir_ / "out" / "summary.json");
  ASSERT_EQ(summary["starts"][0]["nlopt_result"], "FAILURE")
      << "this case no longer makes NLopt fail; choose another";
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(summary["status"], "failed");
  EXPECT_TRUE(contains(summary["message"].get<std::string>(), "start 1: NLopt failed (FAILURE)"))
      << summary["message"];
  EXPECT_TRUE(contains(r.err, "failed: start 1: NLopt failed (FAILURE)")) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out" / "best.json"));
  EXPECT_FALSE(fs::exists(dir_ / "out" / "best_scene.json"));
  EXPECT_FALSE(summary.contains("best"));
  // The best feasible design it evaluated is given for information, with its constraint report,
  // and the start's stop in words.
  const Json& b = summary["best_evaluated"];
  ASSERT_TRUE(b.is_object()) << summary.dump(2);
  ASSERT_EQ(b["constraints"].size(), 1u);
  const Json& c = b["constraints"][0];
  EXPECT_EQ(c["response"], "f1");
  EXPECT_EQ(c["type"], ">=");
  EXPECT_EQ(c["bound"], 20.0);
  EXPECT_EQ(c["value"], b["responses"]["f1"]);
  EXPECT_DOUBLE_EQ(c["margin"].get<double>(), c["value"].get<double>() - 20.0);
  EXPECT_DOUBLE_EQ(c["relative_margin"].get<double>(), c["margin"].get<double>() / 20.0);
  EXPECT_EQ(c["satisfied"], true);
  EXPECT_EQ(summary["starts"][0]["best"]["evaluation"], b["evaluation"]);
  EXPECT_TRUE(contains(summary["starts"][0]["stop_reason"], "NLopt failed")) << summary["starts"];
}

// No feasible design: the study is infeasible, and the start reports no best design (null).
TEST_F(OptimizerStops, AStartWithoutAFeasibleDesignReportsNoBest) {
  Json s = rod("LN_COBYLA", 6);
  s["study"]["constraints"][0][">="] = 1e6;  // f1 >= 1 MHz
  const ProcessResult r = run("infeasible.json", s);
  ASSERT_TRUE(r.exited) << r.how;
  const Json summary = load_json(dir_ / "out" / "summary.json");
  std::printf("%s: %s%s\n", r.how.c_str(), r.err.c_str(), summary["starts"].dump().c_str());
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(summary["status"], "infeasible");
  ASSERT_EQ(summary["starts"].size(), 1u);
  EXPECT_TRUE(summary["starts"][0]["best"].is_null());
  // COBYLA returned to a design (at the upper bound): 6 calls, 5 designs.
  EXPECT_LE(summary["starts"][0]["designs"].get<int>(), 6);
  EXPECT_EQ(summary["starts"][0]["designs"], summary["designs_in_history"]);
  EXPECT_EQ(summary["starts"][0]["nlopt_result"], "MAXEVAL_REACHED");
  EXPECT_FALSE(summary.contains("best_evaluated"));
}

// max_evaluations is the number of designs a start evaluates. A gradient call costs 2n + 1 designs
// (central differences: 3 for the rod's one variable): once NLopt's next call would take a start
// beyond the budget, it is not evaluated and NLopt is stopped; the start reports MAXEVAL_REACHED,
// a normal stop. (NLopt's own call limit, the former meaning, let 10 evaluations cost up to 30
// designs.) The rod's start point is 1 design, NLopt's first call at it 2 more, each further call
// 3: with 10 designs allowed, a start ends after 9, its next call needing 3.
TEST_F(OptimizerStops, AGradientStartStopsWhenItsDesignBudgetIsSpent) {
  for (const std::string algorithm : {"LD_SLSQP", "LD_MMA"}) {
    SCOPED_TRACE(algorithm);
    Json s = rod(algorithm, 10);
    s["study"]["gradient"] = "fd";
    s["study"]["starts"] = 2;
    s["study"]["variables"][0]["initial"] =
        0.09;  // far from the optimum: 10 designs do not reach it
    const ProcessResult r = run("budget.json", s);
    ASSERT_TRUE(r.exited && r.status == 0) << r.how << "\n" << r.err;
    const Json summary = load_json(dir_ / "out" / "summary.json");
    const std::string history = read_text(dir_ / "out" / "history.csv");
    const std::map<int, int> rows = rows_per_start(history);
    std::printf("%s: %s\n", algorithm.c_str(), summary["starts"].dump(1).c_str());
    EXPECT_EQ(summary["status"], "ok");
    EXPECT_EQ(summary["max_evaluations"], 10);
    EXPECT_TRUE(fs::exists(dir_ / "out" / "best.json"));
    ASSERT_EQ(summary["starts"].size(), 2u);
    ASSERT_EQ(rows.size(), 2u);
    for (const Json& st : summary["starts"]) {
      const int index = st["start"];
      SCOPED_TRACE("start " + std::to_string(index));
      EXPECT_EQ(st["nlopt_result"], "MAXEVAL_REACHED");
      EXPECT_TRUE(contains(st["stop_reason"],
                           "the design budget is spent: the start had evaluated "
                           "9 of its 10 designs (max_evaluations) and NLopt's "
                           "next call needed 3 more"))
          << st["stop_reason"];
      EXPECT_EQ(st["designs"], 9);
      EXPECT_EQ(rows.at(index), 9);
      EXPECT_LE(rows.at(index), 10);
      EXPECT_TRUE(st["best"].is_object());
    }
    EXPECT_EQ(summary["designs_in_history"], 18);
    EXPECT_LE(summary["designs_simulated"].get<int>(), 20);

    // --resume replays the designs of history.csv, which count as before: the resumed run stops
    // where this one did, with the same history and best design.
    const std::string best = read_text(dir_ / "out" / "best.json");
    const std::vector<std::string> lines = lines_of(history);
    std::string half;
    for (size_t i = 0; i <= lines.size() / 2; ++i) half += lines[i] + "\n";
    std::ofstream(dir_ / "out" / "history.csv") << half;
    fs::remove(dir_ / "out" / "summary.json");
    std::vector<std::string> args{"run", "budget.json", "-o", "out", "--quiet", "--resume"};
    const ProcessResult resumed =
        testing::run_process(BEAMRAIL_EXECUTABLE, args, dir_, std::chrono::seconds(60));
    ASSERT_TRUE(resumed.exited && resumed.status == 0) << resumed.how << "\n" << resumed.err;
    const Json again = load_json(dir_ / "out" / "summary.json");
    EXPECT_EQ(rows_per_start(read_text(dir_ / "out" / "history.csv")), rows);
    EXPECT_EQ(read_text(dir_ / "out" / "best.json"), best);
    EXPECT_EQ(again["starts"][0]["designs"], 9);
    EXPECT_EQ(again["starts"][0]["nlopt_result"], "MAXEVAL_REACHED");
    EXPECT_LE(again["designs_simulated"].get<int>(), 18 - static_cast<int>(lines.size() / 2));
    fs::remove_all(dir_ / "out");
  }
}

// Without gradients one NLopt call is one design, as before: LN_COBYLA with 10 designs allowed
// evaluates 10 (its first call is the start point) and NLopt itself stops at its limit.
TEST_F(OptimizerStops, ADerivativeFreeStartEvaluatesOneDesignPerCall) {
  Json s = rod("LN_COBYLA", 10);
  s["study"]["variables"][0]["initial"] = 0.09;
  const ProcessResult r = run("cobyla.json", s);
  ASSERT_TRUE(r.exited && r.status == 0) << r.how << "\n" << r.err;
  const Json summary = load_json(dir_ / "out" / "summary.json");
  const Json& st = summary["starts"][0];
  std::printf("%s\n", st.dump(1).c_str());
  EXPECT_EQ(st["nlopt_result"], "MAXEVAL_REACHED");
  EXPECT_EQ(st["stop_reason"],
            "NLopt reached its own limit of max_evaluations (10) calls (without gradients a call "
            "is one design at most)");
  EXPECT_EQ(st["nlopt_evaluations"], 10);
  EXPECT_EQ(st["designs"], 10);
  EXPECT_EQ(rows_per_start(read_text(dir_ / "out" / "history.csv")).at(1), 10);
}

// LD_SLSQP on the rod with no tolerance to stop at (xtol_rel = ftol_rel = 0) reaches the optimum
// and then cannot make progress: NLopt ends ROUNDOFF_LIMITED there. The best design stands (it is
// feasible), with a warning in summary.json and on stderr.
TEST_F(OptimizerStops, RoundoffLimitedIsReportedAsAWarning) {
  Json s = rod("LD_SLSQP", 200);
  s["study"]["xtol_rel"] = 0.0;
  s["study"]["ftol_rel"] = 0.0;
  const ProcessResult r = run("slsqp.json", s);
  std::printf("%s: %s%s", r.how.c_str(), r.out.c_str(), r.err.c_str());
  ASSERT_TRUE(r.exited) << r.how;
  const Json summary = load_json(dir_ / "out" / "summary.json");
  ASSERT_EQ(summary["starts"][0]["nlopt_result"], "ROUNDOFF_LIMITED")
      << "this case no longer ends ROUNDOFF_LIMITED; choose another";
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(summary["status"], "ok");
  ASSERT_EQ(summary["warnings"].size(), 1u);
  EXPECT_TRUE(contains(summary["warnings"][0].get<std::string>(), "ROUNDOFF_LIMITED"));
  EXPECT_TRUE(contains(r.err, "warning: start 1: NLopt stopped early")) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "out" / "best.json"));
}

}  // namespace
}  // namespace beamrail
