// One optimization start at the library level (optimizer/batch/start_runner.hpp,
// start_task.hpp): a start replayed from its own rows evaluates nothing and hands back the same
// rows and result (what --resume relies on, in one process and on every MPI rank); a start packed
// as an MPI task gives the rows and result of the start run directly; a cancelled start records
// no design; a message cut short unpacks to zeros and empty values, never past its end.
#include "optimizer/batch/start_runner.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <mutex>

#include "optimizer/batch/start_task.hpp"
#include "optimizer/batch/wire.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {
namespace {

// A massless 1 m steel cantilever, 10 mm high, with a 2 kg tip body under a 1 mN side load: the
// narrowest section (least mass) whose tip sags at most 1.5 um (sag ~ 1 / width: a width of about
// 13 mm), from 2 starts of COBYLA.
Study load_study_of_test() {
  const Json doc = Json::parse(R"({
    "name": "start_runner",
    "scene": {
      "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
      "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
      "bodies": [{"name": "tip", "mass": 2.0, "inertia": [1e-4, 1e-4, 1e-4], "position": [1, 0, 0]}],
      "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
                 "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq"}],
      "loads": [{"type": "force", "body": "tip", "value": [0, 0, -1e-3]}]
    },
    "analyses": [{"type": "static"}],
    "responses": {"sag": {"quantity": "displacement", "body": "tip", "direction": [0, 0, -1]},
                  "mass": {"quantity": "mass"}},
    "study": {"type": "optimize", "algorithm": "LN_COBYLA", "objective": {"minimize": "mass"},
              "constraints": [{"response": "sag", "<=": 1.5e-6}], "starts": 2, "seed": 5,
              "max_evaluations": 25, "variables": [{"name": "width",
              "pointer": "/scene/sections/sq/width", "lower": 0.005, "upper": 0.02}]}
  })");
  Diagnostics diag;
  std::optional<Study> study = load_study(doc, "start_runner.json", ".", diag);
  EXPECT_TRUE(study) << diag.format();
  return study ? std::move(*study) : Study{};
}

class Rows : public StartSink {
 public:
  void record(const OptimizationRecord& r) override {
    const std::lock_guard<std::mutex> lock(mutex_);
    records.push_back(r);
  }
  void derivatives(const Design&, const Eigen::MatrixXd&) override {}
  std::vector<OptimizationRecord> records;

 private:
  std::mutex mutex_;
};

void expect_same_rows(const std::vector<OptimizationRecord>& a,
                      const std::vector<OptimizationRecord>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].start, b[i].start);
    EXPECT_EQ(a[i].evaluation, b[i].evaluation);
    EXPECT_EQ(a[i].x, b[i].x) << "row " << i;
    EXPECT_EQ(a[i].outcome.responses, b[i].outcome.responses) << "row " << i;
    EXPECT_EQ(a[i].outcome.status, b[i].outcome.status);
    EXPECT_EQ(a[i].objective, b[i].objective);
    EXPECT_EQ(a[i].feasible, b[i].feasible);
  }
}

class StartRunner : public ::testing::Test {
 protected:
  StartRunner() : study_(load_study_of_test()), problem_(study_), evaluator_(study_) {
    task_.index = 2;
    task_.x0 = problem_.start_points().at(1);
    task_.constraint_scales = {1.5e-6};
  }
  Study study_;
  OptimizationProblem problem_;
  DesignEvaluator evaluator_;
  StartTask task_;
  std::atomic<bool> cancel_{false};
};

TEST_F(StartRunner, AStartReplayedFromItsRowsEvaluatesNothingAndHandsBackTheSameRows) {
  DesignCache cache;
  Rows first;
  const StartResult run = run_start(problem_, evaluator_, task_, cache, 1, first, cancel_);
  ASSERT_GE(first.records.size(), 5u);
  EXPECT_EQ(run.cost.simulated, static_cast<long>(first.records.size()));
  EXPECT_EQ(run.designs, static_cast<long>(first.records.size()));
  EXPECT_FALSE(run.stopped);
  long feasible = 0;
  for (const OptimizationRecord& r : first.records) feasible += r.feasible;
  EXPECT_GE(feasible, 1);

  DesignCache replay;  // what --resume reads back: the start's rows
  for (const OptimizationRecord& r : first.records) replay.add(r.x, r.outcome);
  Rows again;
  const StartResult resumed = run_start(problem_, evaluator_, task_, replay, 1, again, cancel_);
  EXPECT_EQ(resumed.cost.simulated, 0);
  EXPECT_EQ(resumed.result, run.result);
  EXPECT_EQ(resumed.designs, run.designs);
  EXPECT_EQ(resumed.nlopt_evaluations, run.nlopt_evaluations);
  EXPECT_EQ(resumed.objective_scale, run.objective_scale);
  expect_same_rows(again.records, first.records);
}

TEST_F(StartRunner, AStartPackedAsATaskGivesTheRowsAndResultOfTheStartRunDirectly) {
  DesignCache cache;
  Rows direct;
  const StartResult expected = run_start(problem_, evaluator_, task_, cache, 1, direct, cancel_);
  std::vector<std::vector<char>> messages;
  const std::vector<char> result = run_start_task(
      evaluator_, 1, pack_start_task(task_, {}),
      [&](std::vector<char> m) { messages.push_back(std::move(m)); }, cancel_);
  Rows sent;
  for (const std::vector<char>& m : messages) unpack_start_message(m, sent);
  expect_same_rows(sent.records, direct.records);
  const StartResult got = unpack_start_result(result);
  EXPECT_EQ(got.index, 2);
  EXPECT_EQ(got.result, expected.result);
  EXPECT_EQ(got.designs, expected.designs);
  EXPECT_EQ(got.nlopt_evaluations, expected.nlopt_evaluations);
  EXPECT_EQ(got.objective_scale, expected.objective_scale);
  EXPECT_EQ(got.cost.simulated, expected.cost.simulated);
  EXPECT_EQ(got.stopped, false);
}

TEST_F(StartRunner, ACancelledStartRecordsNoDesignAndSaysItWasStopped) {
  cancel_ = true;
  DesignCache cache;
  Rows rows;
  const StartResult r = run_start(problem_, evaluator_, task_, cache, 1, rows, cancel_);
  EXPECT_TRUE(rows.records.empty());
  EXPECT_EQ(r.cost.simulated, 0);
  EXPECT_TRUE(r.stopped);
  EXPECT_EQ(r.result, NLOPT_FORCED_STOP);
}

TEST(Wire, AMessageCutShortUnpacksToZerosAndEmptyValues) {
  Packer p;
  p.put<int32_t>(7);
  p.put_string("seven");
  p.put_doubles({1.0, 2.0, 3.0});
  DesignOutcome o;
  o.status = Status::kInvalid;
  o.warnings = 2;
  o.responses = {4.0, 5.0};
  o.message = "wall too thick";
  p.put_outcome(o);
  {
    Unpacker u(p.bytes);
    EXPECT_EQ(u.get<int32_t>(), 7);
    EXPECT_EQ(u.get_string(), "seven");
    EXPECT_EQ(u.get_doubles(), (std::vector<double>{1.0, 2.0, 3.0}));
    const DesignOutcome back = u.get_outcome();
    EXPECT_EQ(back.status, Status::kInvalid);
    EXPECT_EQ(back.warnings, 2);
    EXPECT_EQ(back.responses, o.responses);
    EXPECT_EQ(back.message, o.message);
  }
  // Cut inside the doubles: the vector and all after it come back empty.
  const std::vector<char> cut(p.bytes.begin(), p.bytes.begin() + 4 + 8 + 5 + 8 + 16);
  Unpacker u(cut);
  EXPECT_EQ(u.get<int32_t>(), 7);
  EXPECT_EQ(u.get_string(), "seven");
  EXPECT_TRUE(u.get_doubles().empty());
  EXPECT_EQ(u.get<int32_t>(), 0);
  EXPECT_TRUE(u.get_string().empty());
  // A length beyond the message is refused, not read.
  Packer lying;
  lying.put<int64_t>(int64_t{1} << 60);
  Unpacker v(lying.bytes);
  EXPECT_TRUE(v.get_doubles().empty());
}

}  // namespace
}  // namespace beamrail
