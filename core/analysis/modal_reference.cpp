#include "core/analysis/modal_reference.hpp"

#include <chrono>
#include <cstdio>

#include "core/analysis/modal_integrator.hpp"
#include "core/analysis/static_analysis.hpp"
#include "core/model/data.hpp"
#include "core/model/rotation.hpp"

namespace beamrail {
namespace {

bool refuse(std::string* error, const std::string& what) {
  *error = what;
  return false;
}

}  // namespace

std::string rotation_limit_text() {
  char text[32];
  std::snprintf(text, sizeof text, "%g rad", kModalIntegratorMaxRotation);
  return text;
}

bool modal_reference(const Model& model, const IntegratorOptions& options, OdeContext& context,
                     std::vector<double>& reference, std::vector<std::string>& warnings,
                     InitialLinearization* initial, std::string* error) {
  if (options.about == "initial") return true;
  if (!options.about.empty() && options.about != "static")
    return refuse(error, "the modal integrator: unknown \"about\": \"" + options.about +
                             "\" (expected \"static\" or \"initial\")");
  // From the model's initial configuration (solve_static starts there; so does y0).
  Data data(model);
  StaticOptions statics;
  statics.time = 0.0;
  statics.structure_cache = context.structure_cache;
  const StaticResult equilibrium = solve_static(model, statics, data);
  if (std::chrono::steady_clock::now() > context.deadline) {
    context.timed_out = true;
    return refuse(error,
                  "timeout: the run exceeded its max_seconds budget (in the modal "
                  "integrator's static solve)");
  }
  std::string why;
  if (!equilibrium.ok && equilibrium.no_equilibrium) {
    // The static solver's own account (the load factor it reached, a carriage that left its
    // rail on the way) describes its search, not the run.
    why =
        "the loads at t = 0 push along a direction without stiffness (a free body or mechanism, "
        "such as a carriage driven along its rail): no static equilibrium exists";
  } else if (!equilibrium.ok) {
    why = "no static equilibrium under the loads at t = 0 (" + equilibrium.message + ")";
  } else {
    for (int b = 0; b < model.n_free() && why.empty(); ++b) {
      const int body = model.free_bodies[b];
      const double* r = reference.data() + kStatesPerBody * b;
      const Mat3 a0 = rotation_matrix<double>(Vec4(r[3], r[4], r[5], r[6]));
      if (rotation_vector(data.pose[body].A * a0.transpose()).norm() > kModalIntegratorMaxRotation)
        why = "in the static equilibrium under the loads at t = 0, body \"" +
              model.bodies[body].name + "\" is turned more than " + rotation_limit_text() +
              " from its initial orientation";
    }
  }
  if (!why.empty()) {
    if (options.about == "static")
      return refuse(error, "the modal integrator: " + why +
                               "; \"about\": \"initial\" linearizes "
                               "about the initial state");
    initial->because = why;
    initial->no_equilibrium = !equilibrium.ok && equilibrium.no_equilibrium;
    // auto (max_rotation set) relinearizes where a body turns its limit; modal alone stops.
    const std::string then =
        options.max_rotation > 0.0
            ? " (auto linearizes again as the bodies turn)"
            : " (the run stops if a body turns more than " + rotation_limit_text() + " from there)";
    warnings.push_back("the modal integrator linearized about the initial state: " + why +
                       (equilibrium.ok ? then : ""));
    return true;
  }
  for (int b = 0; b < model.n_free(); ++b) {
    const int body = model.free_bodies[b];
    double* r = reference.data() + kStatesPerBody * b;
    for (int j = 0; j < 3; ++j) r[j] = data.pose[body].u(j);
    for (int j = 0; j < 4; ++j) r[3 + j] = data.q[body](j);
    for (int j = 7; j < kStatesPerBody; ++j) r[j] = 0.0;
  }
  return true;
}

}  // namespace beamrail
