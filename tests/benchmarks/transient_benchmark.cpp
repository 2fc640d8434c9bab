// Whole transient runs: the reference problem of the speed targets (N = 10 and 40 segments, 0.2 s,
// error measured against a tight run), and the wall time per step of chains of 100 ... 10,000
// bodies (scripts/bench fits its growth exponent).
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "core/analysis/transient.hpp"
#include "tests/benchmarks/reference_problem.hpp"

namespace beamrail {
namespace {

struct TipPath {
  std::vector<Vec3> tip;  // tip body centre at every output time
};

int tip_index(const Model& model) {
  for (size_t i = 0; i < model.bodies.size(); ++i)
    if (model.bodies[i].name == "tip") return static_cast<int>(i);
  return -1;
}

TipPath run(const Model& model, const TransientOptions& options, TransientResult* result) {
  TipPath path;
  Data data(model);
  const int tip = tip_index(model);
  *result = run_transient(model, options, data, [&](const TransientSample&, const Data& d) {
    path.tip.push_back(d.pose[tip].u);
  });
  return path;
}

TransientOptions reference_options(const IntegratorOptions& integrator) {
  TransientOptions o;
  o.t_end = 0.2;
  o.output_step = 1e-3;
  o.integrator = integrator;
  return o;
}

// The tight run the errors are measured against: ERK (Verner 8(7)) at rtol 1e-11, atol 1e-12,
// which agrees with BDF and DIRK runs at the same tolerances to 5e-11 of the tip motion.
const TipPath& tight_run(int segments) {
  static std::map<int, TipPath> cache;
  auto it = cache.find(segments);
  if (it == cache.end()) {
    IntegratorOptions io;
    io.method = IntegratorMethod::kErk;
    io.table = "VERNER_8_5_6";
    io.rtol = 1e-11;
    io.atol = 1e-12;
    TransientResult r;
    it = cache.emplace(segments, run(bench::reference_model(segments), reference_options(io), &r))
             .first;
  }
  return it->second;
}

double tip_error(const TipPath& run, const TipPath& reference) {
  double error = 0.0, motion = 0.0;
  for (const Vec3& c : reference.tip) motion = std::max(motion, (c - reference.tip[0]).norm());
  if (run.tip.size() != reference.tip.size()) return NAN;
  for (size_t k = 0; k < run.tip.size(); ++k)
    error = std::max(error, (run.tip[k] - reference.tip[k]).norm());
  return error / motion;
}

// The reference problem with one method at one tolerance (atol = 1e-2 rtol: positions are ~1 m,
// the tip moves ~2 mm).
void ReferenceProblem(benchmark::State& state, const char* method, const char* table, double rtol) {
  const int segments = static_cast<int>(state.range(0));
  const Model model = bench::reference_model(segments);
  IntegratorOptions io;
  io.method = *method_from_name(method);
  io.table = table;
  io.rtol = rtol;
  io.atol = 1e-2 * rtol;
  const TipPath& reference = tight_run(segments);
  TransientResult result;
  TipPath path;
  for (auto _ : state) path = run(model, reference_options(io), &result);
  state.counters["error"] = tip_error(path, reference);
  state.counters["steps"] = static_cast<double>(result.stats.steps);
  state.counters["rhs"] = static_cast<double>(result.stats.rhs_evaluations);
  state.counters["jac"] = static_cast<double>(result.stats.jacobian_evaluations);
  state.counters["ok"] = result.ok;
}
// The runs of the reference problem: name, method, table, rtol, and whether N = 40 is run too.
struct ReferenceRun {
  const char* name;
  const char* method;
  const char* table;
  double rtol;
  bool fine;
};
constexpr ReferenceRun kReferenceRuns[] = {
    {"dirk_esdirk547_rtol1e_5", "dirk", "ESDIRK547L2SA2_7_4_5", 1e-5, true},
    {"dirk_esdirk547_rtol3e_5", "dirk", "ESDIRK547L2SA2_7_4_5", 3e-5, true},
    {"erk_verner_rtol1e_4", "erk", "VERNER_8_5_6", 1e-4, true},
    {"modal_rtol5e_5", "modal", "", 5e-5, true},
    {"modal_rtol8e_5", "modal", "", 8e-5, true},
    {"modal_rtol1e_4", "modal", "", 1e-4, true},
    {"modal_rtol1e_5", "modal", "", 1e-5, true},
    {"bdf_rtol1e_6", "bdf", "", 1e-6, false},  // BDF is stability-limited: 12 s at N = 40
};
const bool kReferenceRegistered = [] {
  for (const ReferenceRun& r : kReferenceRuns) {
    auto* b = benchmark::RegisterBenchmark(
        (std::string("ReferenceProblem/") + r.name).c_str(),
        [r](benchmark::State& state) { ReferenceProblem(state, r.method, r.table, r.rtol); });
    b->Arg(10);
    if (r.fine) b->Arg(40);
    b->Unit(benchmark::kMillisecond)->Iterations(1);
  }
  return true;
}();

// Wall time per step of a chain of N bodies: the reference cantilever in N segments under its step
// load, BDF with the sparse (KLU) solver, stopped after a fixed budget of 300 steps (set-up
// included: the sparsity pattern, the symbolic factorization).
void TransientStep(benchmark::State& state) {
  const int segments = static_cast<int>(state.range(0));
  const Model model = bench::reference_model(segments);
  TransientOptions o;
  o.t_end = 1.0;
  o.output_step = 1.0;
  o.integrator.rtol = 1e-6;
  o.integrator.atol = 1e-8;
  o.integrator.max_steps = 300;
  o.integrator.linear_solver = LinearSolverKind::kSparse;
  TransientResult result;
  double steps = 0.0;
  for (auto _ : state) {
    Data data(model);
    result = run_transient(model, o, data, [](const TransientSample&, const Data&) {});
    steps += static_cast<double>(result.stats.steps);
  }
  state.counters["bodies"] = model.n_free();
  state.counters["steps"] = static_cast<double>(result.stats.steps);
  state.counters["rhs"] = static_cast<double>(result.stats.rhs_evaluations);
  state.counters["jac"] = static_cast<double>(result.stats.jacobian_evaluations);
  // Seconds per step (the counter is inverted: steps per second of wall time, then 1/x).
  state.counters["s_per_step"] =
      benchmark::Counter(steps, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(TransientStep)
    ->Arg(100)
    ->Arg(300)
    ->Arg(1000)
    ->Arg(3000)
    ->Arg(10000)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace beamrail

BENCHMARK_MAIN();
