// Evaluating designs at the library level: evaluate() (optimizer/run/evaluation.hpp) returns its
// results, its result tables as data when asked for, and writes no file; the thread executor
// (optimizer/batch/executor.hpp) hands every design back once, one call at a time, with the
// outcome that evaluating it alone gives, and starts none after its callback says stop or after a
// stop request.
#include "optimizer/batch/executor.hpp"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <set>

#include "core/analysis/stop_request.hpp"
#include "optimizer/run/evaluation.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {
namespace {

namespace fs = std::filesystem;

// A massless 1 m steel cantilever, 10 mm square, with a 2 kg tip body under a 1 mN side load (a
// deflection of 2 um: linear to 1e-12);
// its width swept. Widths below zero are invalid designs.
Json sweep_study() {
  return Json::parse(R"({
    "name": "executor",
    "scene": {
      "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
      "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
      "bodies": [{"name": "tip", "mass": 2.0, "inertia": [1e-4, 1e-4, 1e-4], "position": [1, 0, 0]}],
      "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
                 "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq"}],
      "loads": [{"type": "force", "body": "tip", "value": [0, 0, -1e-3]}]
    },
    "analyses": [{"type": "static"}],
    "responses": {"sag": {"quantity": "displacement", "body": "tip", "direction": [0, 0, -1]}},
    "study": {"type": "sweep", "variables": [{"name": "width",
              "pointer": "/scene/sections/sq/width", "lower": 0.005, "upper": 0.02, "count": 4}]}
  })");
}

Study load(const Json& doc) {
  Diagnostics diag;
  std::optional<Study> study = load_study(doc, "executor.json", ".", diag);
  EXPECT_TRUE(study) << diag.format();
  return study ? std::move(*study) : Study{};
}

TEST(Evaluation, ReturnsTheResponsesAndWritesNothing) {
  const Study study = load(sweep_study());
  std::string pattern = (fs::temp_directory_path() / "beamrail_eval_XXXXXX").string();
  ASSERT_NE(mkdtemp(pattern.data()), nullptr);
  const fs::path before = fs::current_path();
  fs::current_path(pattern);
  const Evaluation ev = evaluate(study, study.model, {});
  fs::current_path(before);
  EXPECT_TRUE(fs::is_empty(pattern));
  fs::remove_all(pattern);
  ASSERT_EQ(ev.status, Status::kOk) << ev.message;
  ASSERT_EQ(ev.responses.size(), 1u);
  // The tip deflection P L^3 / (3 E I), I = b h^3 / 12.
  const double exact = 1e-3 / (3.0 * 2.1e11 * 0.01 * std::pow(0.01, 3) / 12.0);
  EXPECT_NEAR(ev.responses[0] / exact, 1.0, 1e-9);
  ASSERT_EQ(ev.analyses.size(), 1u);
  EXPECT_TRUE(ev.analyses[0].tables.empty());
}

// With result_tables, the static analysis's tables come back as data (the tip's row holds the
// deflection, the beam's two ends the 1 mN load) and still no file is written.
TEST(Evaluation, ReturnsTheResultTablesAsDataAndWritesNothing) {
  const Study study = load(sweep_study());
  std::string pattern = (fs::temp_directory_path() / "beamrail_eval_XXXXXX").string();
  ASSERT_NE(mkdtemp(pattern.data()), nullptr);
  const fs::path before = fs::current_path();
  fs::current_path(pattern);
  EvaluationOptions options;
  options.result_tables = true;
  const Evaluation ev = evaluate(study, study.model, options);
  fs::current_path(before);
  EXPECT_TRUE(fs::is_empty(pattern));
  fs::remove_all(pattern);
  ASSERT_EQ(ev.status, Status::kOk) << ev.message;
  ASSERT_EQ(ev.analyses.size(), 1u);
  const AnalysisReport& a = ev.analyses[0];
  EXPECT_EQ(a.tables, (std::vector<std::string>{"static_displacements.csv", "element_forces.csv"}));
  ASSERT_EQ(a.result_tables.size(), 2u);
  const ResultTable& displacements = a.result_tables[0];
  EXPECT_EQ(displacements.header,
            (std::vector<std::string>{"body", "dx", "dy", "dz", "rx", "ry", "rz"}));
  ASSERT_EQ(displacements.rows.size(), 1u);
  EXPECT_EQ(displacements.rows[0][0], "tip");
  EXPECT_EQ(std::stod(displacements.rows[0][3]), -ev.responses[0]);
  const ResultTable& forces = a.result_tables[1];
  ASSERT_EQ(forces.rows.size(), 2u);  // the beam's two ends
  EXPECT_EQ(forces.rows[0][0], "arm");
  EXPECT_EQ(forces.rows[1][1], "2");
  // The shear at each end: the 1 mN load, to the static tolerance.
  for (const auto& row : forces.rows) {
    double shear = 0.0;
    for (int c = 2; c < 5; ++c) shear = std::max(shear, std::abs(std::stod(row[c])));
    EXPECT_NEAR(shear, 1e-3, 1e-9) << row[1];
  }
}

std::vector<Design> widths() {
  std::vector<Design> d;
  for (int i = 0; i < 24; ++i) d.push_back({i % 6 == 5 ? -0.01 : 0.004 + 0.001 * i});
  return d;
}

TEST(ThreadExecutor, HandsEveryDesignBackOnceOneCallAtATimeAsEvaluatedAlone) {
  const Study study = load(sweep_study());
  const DesignEvaluator evaluator(study);
  const std::vector<Design> designs = widths();
  ThreadExecutor executor(3);
  EXPECT_EQ(executor.ranks(), 1);
  EXPECT_EQ(executor.threads(), 3);
  std::vector<int> calls(designs.size(), 0);
  std::vector<DesignOutcome> outcomes(designs.size());
  std::atomic<int> inside(0);
  bool overlapped = false;
  executor.evaluate(evaluator, designs, [&](long i, const DesignOutcome& o) {
    overlapped = overlapped || ++inside > 1;
    ++calls[i];
    outcomes[i] = o;
    --inside;
    return true;
  });
  EXPECT_FALSE(overlapped);
  for (size_t i = 0; i < designs.size(); ++i) {
    EXPECT_EQ(calls[i], 1) << i;
    const DesignOutcome alone = evaluator.evaluate(designs[i]);
    EXPECT_EQ(outcomes[i].status, alone.status) << i;
    EXPECT_EQ(outcomes[i].status, designs[i][0] < 0 ? Status::kInvalid : Status::kOk) << i;
    ASSERT_EQ(outcomes[i].responses.size(), 1u);
    if (alone.status == Status::kOk) {
      EXPECT_EQ(outcomes[i].responses[0], alone.responses[0]) << i;
    }
  }
}

TEST(ThreadExecutor, StartsNoDesignAfterItsCallbackSaysStopOrAStopRequest) {
  const Study study = load(sweep_study());
  const DesignEvaluator evaluator(study);
  const std::vector<Design> designs = widths();
  ThreadExecutor one(1);
  long handed = 0;
  one.evaluate(evaluator, designs, [&](long, const DesignOutcome&) { return ++handed < 5; });
  EXPECT_EQ(handed, 5);
  request_stop(2);
  handed = 0;
  ThreadExecutor(3).evaluate(evaluator, designs, [&](long, const DesignOutcome&) {
    ++handed;
    return true;
  });
  clear_stop_request();
  EXPECT_EQ(handed, 0);
}

}  // namespace
}  // namespace beamrail
