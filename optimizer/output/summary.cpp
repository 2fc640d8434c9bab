#include "optimizer/output/summary.hpp"

#include <cmath>
#include <string>

#include "core/analysis/dense_product.hpp"
#include "core/model/element_kinds.hpp"
#include "optimizer/output/tables.hpp"
#include "optimizer/output/version.hpp"
#include "optimizer/run/status.hpp"

namespace beamrail {

nlohmann::json json_number(double x) {
  if (!std::isfinite(x)) return nullptr;
  return x;
}

RunOutcome fail_before_designs(const Study& study, const std::filesystem::path& output,
                               const std::string& type, const std::string& message) {
  const nlohmann::json s{{"study", study.name},
                         {"file", study.file},
                         {"beamrail_version", kVersion},
                         {"type", type},
                         {"status", run_status_name(RunStatus::kFailed)},
                         {"message", message},
                         {"warnings", study.input_warnings}};
  RunOutcome outcome;
  outcome.kind = RunOutcome::Kind::kFailed;
  outcome.message = message;
  std::string error;
  if (!write_file_atomically(output / "summary.json", s.dump(2) + "\n", &error))
    outcome.errors.push_back(error);
  return outcome;
}

nlohmann::json model_summary(const Model& model) {
  int generated = 0;
  for (const Body& b : model.bodies) generated += b.generated;
  nlohmann::json out{{"bodies", static_cast<int>(model.bodies.size()) - 1 - generated},
                     {"generated_bodies", generated},
                     {"free_bodies", model.n_free()},
                     {"loads", model.loads.size()},
                     {"states", model.n_states},
                     {"degrees_of_freedom", model.n_dofs}};
  for_each_element_kind([&](auto kind) {
    using Kind = decltype(kind);
    const size_t n = Kind::elements(model).size();
    if (n > 0 || Kind::kCountedWhenNone) out[std::string(Kind::kName) + "s"] = n;
  });
  if (!model.segment_choices.empty()) {
    nlohmann::json chosen = nlohmann::json::array();
    for (const SegmentChoice& c : model.segment_choices)
      chosen.push_back({{"beam", c.beam},
                        {"segments", c.segments},
                        {"first_bending_frequency_hz", c.first_frequency_hz},
                        {"estimated_frequency_error", c.estimated_error},
                        {"frequencies_checked", c.frequencies_checked},
                        {"target_reached", c.reached},
                        {"kept_from_study_scene", c.pinned}});
    out["segments_auto"] = chosen;
  }
  return out;
}

nlohmann::json evaluation_summary(const Study& study, const Model& model, const Evaluation& ev) {
  nlohmann::json s;
  s["study"] = study.name;
  s["file"] = study.file;
  s["beamrail_version"] = kVersion;
  s["status"] = status_name(ev.status);
  s["message"] = ev.message;
  nlohmann::json responses = nlohmann::json::object();
  for (size_t k = 0; k < study.responses.size(); ++k)
    responses[study.responses[k].name] = json_number(ev.responses[k]);
  s["responses"] = responses;
  s["model"] = model_summary(model);
  s["product_threads"] = largest_product_team();  // the modal method's dense products
  nlohmann::json analyses = nlohmann::json::array();
  for (const AnalysisReport& a : ev.analyses) {
    nlohmann::json j{{"name", a.name},
                     {"type", a.type},
                     {"status", a.ok            ? status_name(Status::kOk)
                                : a.interrupted ? status_name(Status::kInterrupted)
                                : a.timed_out   ? status_name(Status::kTimeout)
                                                : status_name(Status::kFailed)},
                     {"message", a.message},
                     {"wall_seconds", a.wall_seconds},
                     {"tables", a.tables}};
    if (!a.load_case.empty()) j["load_case"] = a.load_case;
    if (a.type == "transient") {
      j["integrator"] = a.integrator;
      j["linear_solver"] = a.linear_solver;
      if (!a.phases.empty()) {
        nlohmann::json phases = nlohmann::json::array();
        for (const MethodPhase& p : a.phases)
          phases.push_back({{"t", p.t}, {"method", p.method}, {"reason", p.reason}});
        j["method"] = a.phases.front().method;
        j["method_reason"] = a.phases.front().reason;
        j["phases"] = phases;
        j["phase_count"] = a.phase_count;
      }
      if (a.max_frequency_hz > 0.0) j["max_frequency_hz"] = a.max_frequency_hz;
      if (a.axial_force_states > 0 || a.axial_force_unmeasured > 0)
        j["axial_force_check"] = {{"states", a.axial_force_states},
                                  {"largest", a.axial_force_effect},
                                  {"t", a.axial_force_time},
                                  {"unmeasured", a.axial_force_unmeasured},
                                  {"wall_seconds", a.axial_force_seconds}};
      j["steps"] = a.stats.steps;
      j["rhs_evaluations"] = a.stats.rhs_evaluations;
      j["jacobian_evaluations"] = a.stats.jacobian_evaluations;
      j["nonlinear_iterations"] = a.stats.nonlinear_iterations;
      j["nonlinear_failures"] = a.stats.nonlinear_failures;
      j["error_test_failures"] = a.stats.error_test_failures;
      j["t_reached"] = a.t_reached;
      j["initial"] = a.initial;
      j["energy_initial"] = json_number(a.energy_initial);
      j["energy_final"] = json_number(a.energy_final);
      j["energy_max_change"] = json_number(a.energy_max_change);
      j["energy_max_relative_change"] = json_number(a.energy_max_relative_change);
      if (const auto& v = a.verification) {
        j["verification"] = {
            {"status", v->ok ? status_name(Status::kOk) : status_name(Status::kFailed)},
            {"reason", v->reason},
            {"message", v->message},
            {"rtol", v->rtol},
            {"atol", v->atol},
            {"error", json_number(v->error)},
            {"error_measure",
             "largest distance between body centres of the run and of the tighter run, relative "
             "to the largest distance a body moved (null when none moves more than 1e-12 m)"},
            {"rotation_error", json_number(v->rotation_error)},
            {"rotation_error_measure",
             "largest angle between body orientations of the run and of the tighter run, "
             "relative to the largest angle a body turned (null when none turns more than 1e-9 "
             "rad)"},
            {"tolerances", json_number(v->tolerances)},
            {"rotation_tolerances", json_number(v->rotation_tolerances)},
            {"wall_seconds", v->stats.wall_seconds},
            {"steps", v->stats.steps},
            {"rhs_evaluations", v->stats.rhs_evaluations},
            {"jacobian_evaluations", v->stats.jacobian_evaluations}};
        if (v->fixed_step > 0.0) j["verification"]["fixed_step"] = v->fixed_step;
        if (v->max_step > 0.0) j["verification"]["max_step"] = v->max_step;
        j["verification"]["beside"] = v->beside;
      }
      if (const auto& r = a.refinement) {
        const Verification& f = r->first_run;
        j["refinement"] = {
            {"reason",
             "the run at the tolerances asked was more than 10 times its tolerance off its "
             "verification rerun; the results, steps and verification reported are those of "
             "the run at the rerun's tolerances"},
            {"rtol", f.rtol},
            {"atol", f.atol},
            {"first_run",
             {{"error", json_number(f.error)},
              {"rotation_error", json_number(f.rotation_error)},
              {"tolerances", json_number(f.tolerances)},
              {"rotation_tolerances", json_number(f.rotation_tolerances)},
              {"steps", r->first_stats.steps},
              {"wall_seconds", r->first_stats.wall_seconds},
              {"verification_wall_seconds", f.stats.wall_seconds},
              {"verification_beside", f.beside}}}};
      }
    }
    if (a.statics) {
      const StaticResult& r = *a.statics;
      nlohmann::json st{{"converged", r.ok},
                        {"iterations", r.iterations},
                        {"load_steps", r.load_steps},
                        {"residual_norm", json_number(r.residual_norm)},
                        {"reference_force", json_number(r.reference_force)},
                        {"rounding_floor", json_number(r.rounding_floor)},
                        {"last_correction", json_number(r.correction)},
                        {"singular_directions", r.singular_directions},
                        {"negative_stiffness_directions", r.negative_directions},
                        {"flutter_pairs", r.flutter_pairs},
                        {"wall_seconds", r.wall_seconds}};
      if (!r.path.empty()) {
        st["control"] = "arc_length";
        st["path_points"] = r.path.size();
        st["limit_load_factor"] = json_number(r.limit_load_factor);  // null: none passed
      }
      if (a.type == "static")
        j.update(st);
      else
        j[a.type == "transient" ? "initial_equilibrium" : "equilibrium"] = st;
    }
    if (a.type == "modal") {
      j["about"] = a.about;
      j["eigensolver"] = a.eigensolver;
      j["elastic_modes"] = a.modes;
      j["rigid_body_modes"] = a.rigid_modes;
      j["shift"] = json_number(a.shift);
      j["largest_noise"] = json_number(a.noise);
      j["stiffness_asymmetry"] = json_number(a.asymmetry);
      j["eigenproblem"] = a.nonsymmetric ? "non-symmetric" : "symmetric";
      nlohmann::json captured = nlohmann::json::object();
      for (int d = 0; d < 6; ++d) captured[kDirectionNames[d]] = a.effective_mass_captured(d);
      j["effective_mass_captured"] = captured;
    }
    if (a.type == "buckling") {
      j["eigensolver"] = a.eigensolver;
      nlohmann::json factors = nlohmann::json::array();
      for (double f : a.factors) factors.push_back(json_number(f));
      j["factors"] = factors;
      j["positive_factors"] = a.positive_factors;
    }
    analyses.push_back(j);
  }
  s["analyses"] = analyses;
  s["wall_seconds"] = ev.wall_seconds;
  std::vector<std::string> warnings = study.input_warnings;
  warnings.insert(warnings.end(), ev.warnings.begin(), ev.warnings.end());
  s["warnings"] = warnings;
  return s;
}

}  // namespace beamrail
