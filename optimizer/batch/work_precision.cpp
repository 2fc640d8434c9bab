#include "optimizer/batch/work_precision.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>

#include "core/analysis/stop_request.hpp"
#include "optimizer/batch/mpi_job.hpp"
#include "optimizer/batch/wire.hpp"

namespace beamrail {
namespace {

struct RunRecord {
  TransientResult result;
  Trajectory trajectory;
};

RunRecord run(const Model& model, TransientOptions options) {
  RunRecord r;
  r.trajectory = trajectory_of(model);
  Data data(model);
  r.result = run_transient(model, options, data, [&r](const TransientSample& s, const Data& d) {
    r.trajectory.record(s, d);
  });
  return r;
}

// The study's transient analysis as every run starts it: no time budget of its own.
TransientOptions base_options(const Study& study) {
  const AnalysisSpec& analysis =
      study.analyses[find_analysis(study, AnalysisSpec::Type::kTransient)];
  TransientOptions base = analysis.transient;
  base.max_seconds = 0.0;
  return base;
}

void put_trajectory(Packer& p, const Trajectory& t) {
  p.put<int64_t>(static_cast<int64_t>(t.bodies.size()));
  for (int b : t.bodies) p.put<int32_t>(b);
  p.put_doubles(t.times);
  std::vector<double> xyz;
  xyz.reserve(3 * t.positions.size());
  for (const Vec3& v : t.positions) xyz.insert(xyz.end(), {v.x(), v.y(), v.z()});
  p.put_doubles(xyz);
  std::vector<double> quaternions;
  quaternions.reserve(4 * t.orientations.size());
  for (const Vec4& q : t.orientations)
    quaternions.insert(quaternions.end(), {q(0), q(1), q(2), q(3)});
  p.put_doubles(quaternions);
}

Trajectory get_trajectory(Unpacker& u) {
  Trajectory t;
  const long n = static_cast<long>(u.get<int64_t>());
  for (long i = 0; i < n && i < (1L << 30); ++i) t.bodies.push_back(u.get<int32_t>());
  t.times = u.get_doubles();
  const std::vector<double> xyz = u.get_doubles();
  for (size_t i = 0; i + 2 < xyz.size(); i += 3)
    t.positions.emplace_back(xyz[i], xyz[i + 1], xyz[i + 2]);
  const std::vector<double> quaternions = u.get_doubles();
  for (size_t i = 0; i + 3 < quaternions.size(); i += 4)
    t.orientations.emplace_back(quaternions[i], quaternions[i + 1], quaternions[i + 2],
                                quaternions[i + 3]);
  return t;
}

std::vector<char> pack_run(const PrecisionRun& r) {
  Packer p;
  p.put<int64_t>(r.index);
  p.put_string(r.method);
  p.put<double>(r.rtol);
  p.put<double>(r.atol);
  p.put<double>(r.error);
  p.put<double>(r.rotation_error);
  p.put<double>(r.stats.wall_seconds);
  p.put<int64_t>(r.stats.steps);
  p.put<int64_t>(r.stats.rhs_evaluations);
  p.put<int64_t>(r.stats.jacobian_evaluations);
  p.put_string(r.linear_solver);
  p.put<int32_t>((r.ok ? 1 : 0) | (r.timed_out ? 2 : 0) | (r.interrupted ? 4 : 0));
  return std::move(p.bytes);
}

}  // namespace

PrecisionRun measure_run(const Study& study, long index, const Trajectory& reference,
                         SparseStructureCache* structures) {
  const WorkPrecisionPlan& plan = study.design->work_precision;
  const size_t n_rtols = plan.rtols.size();
  const WorkPrecisionPlan::Method& method = plan.methods.at(static_cast<size_t>(index) / n_rtols);
  const double rtol = plan.rtols.at(static_cast<size_t>(index) % n_rtols);
  TransientOptions options = base_options(study);
  options.structure_cache = structures;
  options.integrator = method.integrator;
  options.integrator.rtol = rtol;
  options.integrator.atol = rtol * plan.atol_scale;
  options.max_seconds = plan.max_seconds;
  const RunRecord r = run(study.model, options);
  PrecisionRun out;
  out.index = index;
  out.method = method.label;
  out.rtol = rtol;
  out.atol = options.integrator.atol;
  out.ok = r.result.ok;
  out.timed_out = r.result.timed_out;
  out.interrupted = r.result.interrupted;
  out.error = r.result.ok ? trajectory_error(r.trajectory, reference)
                          : std::numeric_limits<double>::quiet_NaN();
  out.rotation_error = r.result.ok ? trajectory_rotation_error(r.trajectory, reference)
                                   : std::numeric_limits<double>::quiet_NaN();
  out.stats = r.result.stats;
  out.linear_solver = r.result.linear_solver;
  return out;
}

std::vector<char> pack_precision_task(long index, const Trajectory& reference) {
  Packer p;
  p.put<int64_t>(index);
  put_trajectory(p, reference);
  return std::move(p.bytes);
}

std::vector<char> run_precision_task(const Study* study, const std::vector<char>& task,
                                     SparseStructureCache* structures) {
  // Every run of a rank integrates the same model: its structure is analysed once.
  static SparseStructureCache own;
  Unpacker u(task);
  const long index = static_cast<long>(u.get<int64_t>());
  try {
    if (study && study->design && study->design->type == DesignStudy::Type::kWorkPrecision)
      return pack_run(
          measure_run(*study, index, get_trajectory(u), structures ? structures : &own));
  } catch (...) {  // any type: a failed run
  }
  {
    PrecisionRun failed;  // what rank 0 reports as a failed run
    failed.index = index;
    return pack_run(failed);
  }
}

PrecisionRun unpack_precision_run(const std::vector<char>& bytes) {
  Unpacker u(bytes);
  PrecisionRun r;
  r.index = static_cast<long>(u.get<int64_t>());
  r.method = u.get_string();
  r.rtol = u.get<double>();
  r.atol = u.get<double>();
  r.error = u.get<double>();
  r.rotation_error = u.get<double>();
  r.stats.wall_seconds = u.get<double>();
  r.stats.steps = static_cast<long>(u.get<int64_t>());
  r.stats.rhs_evaluations = static_cast<long>(u.get<int64_t>());
  r.stats.jacobian_evaluations = static_cast<long>(u.get<int64_t>());
  r.linear_solver = u.get_string();
  const int32_t flags = u.get<int32_t>();
  r.ok = flags & 1, r.timed_out = flags & 2, r.interrupted = flags & 4;
  return r;
}

PrecisionReference run_reference(const Study& study) {
  TransientOptions options = base_options(study);
  PrecisionReference reference;
  options.structure_cache = reference.structures.get();
  options.integrator = study.design->work_precision.reference;
  RunRecord r = run(study.model, options);
  reference.result = std::move(r.result);
  reference.trajectory = std::move(r.trajectory);
  return reference;
}

WorkPrecisionResult measure_work_precision(const Study& study, const PrecisionReference& reference,
                                           const std::function<bool(const PrecisionRun&)>& done) {
  const WorkPrecisionPlan& plan = study.design->work_precision;
  WorkPrecisionResult result;
  result.planned = static_cast<long>(plan.methods.size() * plan.rtols.size());
  SparseStructureCache& structures = *reference.structures;
  MpiJob* job = mpi_job();
  if (!job || job->size() < 2) {
    // One after another, so that timings are not shared with other runs.
    for (long i = 0; i < result.planned && !stop_requested(); ++i) {
      const PrecisionRun r = measure_run(study, i, reference.trajectory, &structures);
      if (r.interrupted) {  // not a measurement
        result.interrupted = true;
        break;
      }
      result.runs.push_back(r);
      if (!done(r)) break;
    }
    return result;
  }
  // Over the ranks, one run at a time per rank: each compares its run with the reference sent.
  result.ranks = job->size();
  std::vector<std::vector<char>> tasks;
  for (long i = 0; i < result.planned; ++i)
    tasks.push_back(pack_precision_task(i, reference.trajectory));
  TaskCallbacks callbacks;
  callbacks.run_here =
      [&](const std::vector<char>& task, const std::function<void(std::vector<char>)>&,
          const std::atomic<bool>&) { return run_precision_task(&study, task, &structures); };
  callbacks.message = [](long, const std::vector<char>&) { return true; };
  result.runs_per_rank.assign(job->size(), 0);
  callbacks.finished = [&](long, int rank, const std::vector<char>& bytes) {
    ++result.runs_per_rank[rank];
    PrecisionRun r = unpack_precision_run(bytes);
    if (r.method.empty()) {  // a run that could not start on its rank
      const size_t n_rtols = plan.rtols.size();
      r.method = plan.methods.at(static_cast<size_t>(r.index) / n_rtols).label;
      r.rtol = plan.rtols.at(static_cast<size_t>(r.index) % n_rtols);
      r.atol = r.rtol * plan.atol_scale;
    }
    if (r.interrupted) {
      result.interrupted = true;
      return false;
    }
    result.runs.push_back(r);
    return done(r);
  };
  job->run_tasks(study, 1, TaskKind::kPrecisionRun, tasks, callbacks);
  std::sort(result.runs.begin(), result.runs.end(),
            [](const PrecisionRun& a, const PrecisionRun& b) { return a.index < b.index; });
  return result;
}

}  // namespace beamrail
