// How a transient run ends when it cannot go on: the step budget max_steps holds for the whole
// run (across output steps and the restarts at load jumps), options that cannot run are refused
// before anything runs, a load that overflows ends the run as
// failed in bounded time, the integrators' flags come out in words, and a stop request ends the
// run as interrupted with the samples delivered so far.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <csignal>
#include <functional>
#include <string>
#include <vector>

#include "core/analysis/stop_request.hpp"
#include "core/analysis/transient.hpp"
#include "tests/support/transient_run.hpp"

namespace beamrail {
namespace {

using testing::scene_from_json;
using testing::simulate;
using testing::TransientRun;

// A steel cantilever (1 m, 10 mm square) with a 1 kg tip body; `loads` is spliced in.
Model cantilever(const std::string& loads) {
  return scene_from_json(R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.1e10, "density": 7850}},
    "sections": {"sq10": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [{"name": "tip", "mass": 1.0, "inertia": [0.001, 0.001, 0.001],
                "position": [1, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel",
               "section": "sq10"}],
    "loads": )" + loads + "}");
}

TransientOptions run_options(const std::string& method, double t_end, double output_step) {
  TransientOptions o;
  o.t_end = t_end;
  o.output_step = output_step;
  o.integrator.method = *method_from_name(method);
  o.max_seconds = 60.0;  // a guard: every run here ends in well under a second
  return o;
}

const std::vector<std::string> kMethods = {"bdf", "adams", "dirk", "erk", "modal"};
const std::vector<std::string> kSundialsMethods = {"bdf", "adams", "dirk", "erk"};

// 100 output steps need more than 50 steps with every method (the modal integrator takes one
// step per output step here, the others more); a per-output-step budget of 50 would let them all
// finish.
TEST(TransientLimits, MaxStepsIsTheBudgetOfTheWholeRun) {
  const Model model = cantilever(R"([{"type": "force", "body": "tip", "value": [0, -1, 0]}])");
  for (const std::string& method : kMethods) {
    SCOPED_TRACE(method);
    TransientOptions o = run_options(method, 1.0, 0.01);
    o.integrator.max_steps = 50;
    const auto run = simulate(model, o);
    std::printf("%s, max_steps 50: %s at t = %.4g after %ld steps: %s\n", method.c_str(),
                run.result.ok ? "ok" : "failed", run.result.t_reached, run.result.stats.steps,
                run.result.message.c_str());
    EXPECT_FALSE(run.result.ok);
    EXPECT_FALSE(run.result.timed_out);
    EXPECT_LE(run.result.stats.steps, 50);
    EXPECT_LT(run.result.t_reached, 1.0);
    EXPECT_NE(run.result.message.find("max_steps"), std::string::npos) << run.result.message;
  }
}

// A second load steps up at 0.25 s: the integrator restarts there. The run to 0.3 s integrates
// [0, 0.25] as the run to 0.25 s does, then a little more: its counts are larger (counts of the
// last piece alone would be smaller), and a budget of two steps more than the first piece takes is
// too small for it (a budget per piece would be plenty).
TEST(TransientLimits, StepsAndBudgetCountAcrossTheRestartsAtLoadJumps) {
  const Model model = cantilever(
      R"([{"type": "force", "body": "tip", "value": [0, -1, 0]},
          {"type": "force", "body": "tip", "value": [0, -1, 0], "time": {"type": "step",
           "at": 0.25}}])");
  for (const std::string& method : kSundialsMethods) {
    SCOPED_TRACE(method);
    const auto first = simulate(model, run_options(method, 0.25, 0.05));
    const auto whole = simulate(model, run_options(method, 0.3, 0.05));
    ASSERT_TRUE(first.result.ok) << first.result.message;
    ASSERT_TRUE(whole.result.ok) << whole.result.message;
    const SolverStats &a = first.result.stats, &b = whole.result.stats;
    std::printf("%s: to 0.25 s %ld steps, %ld rhs; to 0.3 s %ld steps, %ld rhs\n", method.c_str(),
                a.steps, a.rhs_evaluations, b.steps, b.rhs_evaluations);
    EXPECT_GT(b.steps, a.steps);
    EXPECT_GT(b.rhs_evaluations, a.rhs_evaluations);

    TransientOptions tight = run_options(method, 0.3, 0.05);
    tight.integrator.max_steps = a.steps + 2;
    const auto cut = simulate(model, tight);
    EXPECT_FALSE(cut.result.ok);
    EXPECT_LE(cut.result.stats.steps, a.steps + 2);
    EXPECT_NE(cut.result.message.find("max_steps"), std::string::npos) << cut.result.message;
  }
}

// A force ramping to 1e300 N from 0.1 s: the forces overflow right after 0.1 s. Every method must
// end the run as failed (not run on with ever smaller steps until a budget stops it).
TEST(TransientLimits, AnOverflowingLoadEndsTheRunAsFailed) {
  const Model model = cantilever(
      R"([{"type": "force", "body": "tip", "value": [0, -1e300, 0], "time": {"type": "ramp",
           "from": 0.1, "to": 0.2}}])");
  for (const std::string& method : kSundialsMethods) {
    SCOPED_TRACE(method);
    TransientOptions o = run_options(method, 1.0, 0.01);
    o.max_seconds = 20.0;
    const auto run = simulate(model, o);
    std::printf("%s: %s at t = %.6g after %ld steps, %.3f s: %s\n", method.c_str(),
                run.result.ok ? "ok" : "failed", run.result.t_reached, run.result.stats.steps,
                run.result.stats.wall_seconds, run.result.message.c_str());
    EXPECT_FALSE(run.result.ok);
    EXPECT_FALSE(run.result.timed_out) << "ran on until the guard of 20 s stopped it";
    EXPECT_NE(run.result.message.find("non-finite"), std::string::npos) << run.result.message;
    EXPECT_NEAR(run.result.t_reached, 0.1, 1e-9);
    // The samples up to the overflow were delivered, none after it.
    ASSERT_FALSE(run.samples.empty());
    EXPECT_NEAR(run.samples.back().sample.t, 0.1, 1e-12);
    for (const auto& s : run.samples) EXPECT_TRUE(std::isfinite(s.sample.energy())) << s.sample.t;
  }
}

// CVODE and ARKODE return numbers; the run's message must say in words what went wrong and what to
// do, naming the flag. An end time below what the arithmetic can step to is refused as ILL_INPUT.
TEST(TransientLimits, IntegratorFlagsComeOutInWords) {
  const Model model = cantilever(R"([{"type": "force", "body": "tip", "value": [0, -1, 0]}])");
  for (const std::string& method : kSundialsMethods) {
    SCOPED_TRACE(method);
    const auto run = simulate(model, run_options(method, 1e-300, 1e-300));
    std::printf("%s, t_end 1e-300: %s\n", method.c_str(), run.result.message.c_str());
    ASSERT_FALSE(run.result.ok);
    const std::string& m = run.result.message;
    EXPECT_EQ(m.find("solver flag"), std::string::npos) << m;
    EXPECT_NE(m.find(method == "bdf" || method == "adams" ? "CV_ILL_INPUT" : "ARK_ILL_INPUT"),
              std::string::npos)
        << m;
    EXPECT_NE(m.find("check t_end, output_step"), std::string::npos) << m;
  }
}

// A stop request (what SIGINT and SIGTERM make) ends a run as interrupted at its next
// right-hand side, keeping the samples delivered so far.
TEST(TransientLimits, AStopRequestEndsTheRunAsInterrupted) {
  const Model model = cantilever(R"([{"type": "force", "body": "tip", "value": [0, -1, 0]}])");
  for (const std::string& method : kMethods) {
    SCOPED_TRACE(method);
    Data data(model);
    int samples = 0;
    const TransientResult r = run_transient(model, run_options(method, 1.0, 0.01), data,
                                            [&samples](const TransientSample&, const Data&) {
                                              if (++samples == 5) request_stop(SIGINT);
                                            });
    clear_stop_request();
    std::printf("%s: %s at t = %g after %d samples\n", method.c_str(), r.message.c_str(),
                r.t_reached, samples);
    EXPECT_FALSE(r.ok);
    EXPECT_TRUE(r.interrupted);
    EXPECT_FALSE(r.timed_out);
    EXPECT_EQ(r.message, "interrupted");
    EXPECT_EQ(samples, 5);
    EXPECT_LT(r.t_reached, 0.05 + 1e-12);
  }
}

// A run's own cancel flag (TransientOptions::cancel: a verification rerun beside a run that
// failed) ends it as a stop request does, and no other run: a run beside it, without the flag,
// goes on to t_end. Set from another thread while the run goes, and set before it starts.
TEST(TransientLimits, ACancelFlagEndsThatRunAlone) {
  const Model model = cantilever(R"([{"type": "force", "body": "tip", "value": [0, -1, 0]}])");
  std::vector<std::string> methods = kMethods;
  methods.push_back("auto");
  for (const std::string& method : methods) {
    SCOPED_TRACE(method);
    std::atomic<bool> cancel{false};
    TransientOptions cancelled = run_options(method, 1.0, 0.01);
    cancelled.cancel = &cancel;
    Data data(model), other_data(model);
    int samples = 0;
    const TransientResult r =
        run_transient(model, cancelled, data, [&](const TransientSample&, const Data&) {
          if (++samples == 5) {
            // The other run, with no flag, while this one's flag is set.
            cancel.store(true);
            const TransientResult other =
                run_transient(model, run_options(method, 0.05, 0.01), other_data, nullptr);
            EXPECT_TRUE(other.ok) << other.message;
            EXPECT_DOUBLE_EQ(other.t_reached, 0.05);
          }
        });
    std::printf("%s: %s at t = %g after %d samples\n", method.c_str(), r.message.c_str(),
                r.t_reached, samples);
    EXPECT_FALSE(r.ok);
    EXPECT_TRUE(r.interrupted);
    EXPECT_EQ(r.message, "interrupted");
    EXPECT_EQ(samples, 5);
    EXPECT_LT(r.t_reached, 0.05 + 1e-12);
    EXPECT_EQ(stop_requested(), 0);
    // Set before the run: nothing past the initial state.
    Data fresh(model);
    int first = 0;
    const TransientResult none = run_transient(
        model, cancelled, fresh, [&first](const TransientSample&, const Data&) { ++first; });
    EXPECT_TRUE(none.interrupted);
    EXPECT_LE(none.t_reached, 0.0);
    EXPECT_LE(first, 1);
  }
}

// Options a C++ caller gets wrong are refused before anything runs (TransientOptions::IsValid),
// the reason naming the option: an output step of 0 (its step count would be an undefined
// float-to-int conversion), non-finite or negative times and tolerances, an order beyond the
// method's range, an option of another method. No sample is delivered.
TEST(TransientLimits, OptionsThatCannotRunAreRefusedNamingTheOption) {
  const Model model = cantilever(R"([{"type": "force", "body": "tip", "value": [0, -1, 0]}])");
  struct Case {
    const char* named;
    std::function<void(TransientOptions&)> spoil;
  };
  const Case cases[] = {
      {"output_step", [](TransientOptions& o) { o.output_step = 0.0; }},
      {"output_step", [](TransientOptions& o) { o.output_step = -1e-3; }},
      {"output_step", [](TransientOptions& o) { o.output_step = NAN; }},
      {"t_end", [](TransientOptions& o) { o.t_end = INFINITY; }},
      {"1e8 output rows", [](TransientOptions& o) { o.output_step = 1e-12; }},
      {"max_seconds", [](TransientOptions& o) { o.max_seconds = -1.0; }},
      {"rtol", [](TransientOptions& o) { o.integrator.rtol = 0.0; }},
      {"atol", [](TransientOptions& o) { o.integrator.atol = NAN; }},
      {"orders go from 1 to 5", [](TransientOptions& o) { o.integrator.max_order = 6; }},
      {"orders go from 1 to 12",
       [](TransientOptions& o) {
         o.integrator.method = IntegratorMethod::kAdams;
         o.integrator.max_order = 13;
       }},
      {"stability_limit_detection",
       [](TransientOptions& o) {
         o.integrator.method = IntegratorMethod::kDirk;
         o.integrator.stability_limit_detection = true;
       }},
      {"max_steps", [](TransientOptions& o) { o.integrator.max_steps = 0; }},
      {"fixed_step must be",
       [](TransientOptions& o) {
         o.integrator.method = IntegratorMethod::kDirk;
         o.integrator.fixed_step = -1e-4;
       }},
      {"fixed_step applies", [](TransientOptions& o) { o.integrator.fixed_step = 1e-4; }},
      {"max_step and initial_step do not apply",
       [](TransientOptions& o) {
         o.integrator.method = IntegratorMethod::kErk;
         o.integrator.fixed_step = 1e-4;
         o.integrator.max_step = 1e-3;
       }},
      {"about", [](TransientOptions& o) { o.integrator.about = "static"; }},
  };
  std::string why;
  ASSERT_TRUE(run_options("bdf", 0.01, 1e-3).IsValid(&why)) << why;
  for (const Case& c : cases) {
    TransientOptions o = run_options("bdf", 0.01, 1e-3);
    c.spoil(o);
    why.clear();
    EXPECT_FALSE(o.IsValid(&why)) << c.named;
    EXPECT_NE(why.find(c.named), std::string::npos) << c.named << ": " << why;
    const TransientRun run = simulate(model, o);
    EXPECT_FALSE(run.result.ok) << c.named;
    EXPECT_TRUE(run.samples.empty()) << c.named;
    EXPECT_NE(run.result.message.find(c.named), std::string::npos) << run.result.message;
  }
  for (const char* name : {"bdf", "adams", "dirk", "erk", "modal"})
    EXPECT_STREQ(method_name(*method_from_name(name)), name);
  EXPECT_FALSE(method_from_name("rk4"));
}

}  // namespace
}  // namespace beamrail
