#include "core/analysis/transient.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <stdexcept>

#include "core/analysis/deformation_check.hpp"
#include "core/analysis/integrators.hpp"
#include "core/analysis/sundials_support.hpp"
#include "core/model/dynamics.hpp"
#include "core/model/forces.hpp"

namespace beamrail {
namespace {

TransientSample sample_at(const Model& model, Data& data, double t, const double* y) {
  set_state(model, data, y);
  compute_wrenches(model, data, t);
  TransientSample s;
  s.t = t;
  s.kinetic = kinetic_energy(model, data);
  s.elastic = data.elastic_energy;
  s.gravity = gravity_energy(model, data);
  return s;
}

std::vector<double> load_breakpoints(const Model& model, double t_end) {
  std::vector<double> all, inside;
  for (const Load& load : model.loads) load.time.append_breakpoints(all);
  std::sort(all.begin(), all.end());
  for (double t : all)
    if (t > 0.0 && t < t_end && (inside.empty() || t > inside.back())) inside.push_back(t);
  return inside;
}

}  // namespace

TransientResult run_transient(const Model& model, const TransientOptions& options, Data& data,
                              const TransientObserver& observer) {
  TransientResult result;
  const auto start = std::chrono::steady_clock::now();
  const IntegratorOptions& io = options.integrator;
  DeformationCheck deformation(model);
  try {
    SundialsContext ctx;
    OdeContext context(model, data);
    context.structure_cache = options.structure_cache;
    if (options.max_seconds > 0.0)
      context.deadline = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                     std::chrono::duration<double>(options.max_seconds));
    const long n = model.n_states;
    SerialVector y(n, ctx);
    if (options.initial_state.empty())
      initial_state(model, y.data());
    else if (static_cast<long>(options.initial_state.size()) == n)
      std::copy(options.initial_state.begin(), options.initial_state.end(), y.data());
    else
      throw std::invalid_argument("the initial state has " +
                                  std::to_string(options.initial_state.size()) +
                                  " entries; the model has " + std::to_string(n) + " states");
    std::string error;
    const std::unique_ptr<Integrator> integrator = make_integrator(io, context, ctx, y, &error);
    if (!integrator) {
      result.message = error;
      result.timed_out = context.timed_out;
      result.stats.wall_seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      return result;
    }
    result.linear_solver = integrator->linear_solver;
    result.warnings = integrator->warnings;
    result.jacobian_nonzeros = integrator->nnz;

    const auto deliver = [&](double t) {
      const TransientSample s = sample_at(model, data, t, y.data());
      deformation.observe(model, data, t);
      if (observer) observer(s, data);
    };
    deliver(0.0);

    const std::vector<double> breakpoints = load_breakpoints(model, options.t_end);
    size_t next_break = 0;
    const long n_out =
        std::max(1L, static_cast<long>(std::ceil(options.t_end / options.output_step - 1e-9)));
    double t = 0.0;
    result.ok = true;
    for (long k = 1; k <= n_out && result.ok; ++k) {
      const double t_out = std::min(static_cast<double>(k) * options.output_step, options.t_end);
      while (t < t_out) {
        // Never step across a load's jump: stop there and restart the method.
        const bool at_break = next_break < breakpoints.size();
        const double stop = at_break ? breakpoints[next_break] : options.t_end;
        const int flag = integrator->advance(std::min(t_out, stop), stop, y, &t);
        if (flag < 0) {
          result.ok = false;
          result.timed_out = context.timed_out;
          result.interrupted = context.interrupted;
          result.message = context.interrupted ? "interrupted" : integrator->failure(flag);
          break;
        }
        if (at_break && t >= stop) {
          ++next_break;
          normalize_quaternions(model, y.data());
          integrator->restart(t, y);
        }
      }
      if (result.ok) deliver(t_out);
      // An element outside the range of its law ends the run (checked at accepted states).
      if (std::string range = element_out_of_range(model, data); result.ok && !range.empty()) {
        result.ok = false;
        char when[64];
        std::snprintf(when, sizeof when, "at t = %.6g s, ", t_out);
        result.message = when + range;
      }
    }
    result.t_reached = t;
    result.stats = integrator->stats();
    result.phases = integrator->phases(&result.phase_count);
    for (const std::string& w : integrator->warnings)  // auto's arrive during the run
      if (std::find(result.warnings.begin(), result.warnings.end(), w) == result.warnings.end())
        result.warnings.push_back(w);
  } catch (const std::exception& e) {
    result.ok = false;
    result.message = e.what();
  }
  for (size_t r = 0; r < model.rails.size(); ++r)
    if (data.rail_floored_ever[r])
      result.warnings.push_back("rail \"" + model.rails[r].name + "\" reached its min_length");
  // Checked at the output samples: accepted states only, never Newton trial states.
  for (std::string& w : deformation.warnings(model, true)) result.warnings.push_back(std::move(w));
  result.stats.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace beamrail
