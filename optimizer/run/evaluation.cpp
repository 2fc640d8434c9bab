#include "optimizer/run/analysis_runner.hpp"

namespace beamrail {
namespace evaluation_detail {
namespace {

AnalysisFault analysis_fault = nullptr;  // set_analysis_fault

}  // namespace

bool Runner::run(int index) {
  if (analysis_fault) analysis_fault(study_, model_, index);
  const AnalysisSpec& spec = study_.analyses[index];
  AnalysisReport report;
  report.type = type_name(spec.type);
  report.name = spec.name;
  report.load_case = spec.load_case;
  switch (spec.type) {
    case AnalysisSpec::Type::kStatic:
      run_static(index, report);
      break;
    case AnalysisSpec::Type::kModal:
      run_modal(index, report);
      break;
    case AnalysisSpec::Type::kBuckling:
      run_buckling(index, report);
      break;
    case AnalysisSpec::Type::kTransient:
      run_transient_analysis(index, report);
      break;
  }
  const bool ok = report.ok;
  if (!ok) {
    ev_.status = report.interrupted ? Status::kInterrupted
                 : report.timed_out ? Status::kTimeout
                                    : Status::kFailed;
    ev_.message = report.type + " analysis";
    if (study_.analyses.size() > 1 || spec.name != report.type)
      ev_.message += " \"" + spec.name + "\"";
    ev_.message += ": " + report.message;
  }
  ev_.analyses.push_back(std::move(report));
  return ok;
}

const Model& Runner::case_model(const std::string& load_case) {
  bool all = true;
  for (const Load& load : model_.loads) all = all && applies_in_case(load, load_case);
  if (all) return model_;
  auto it = states_->case_models.find(load_case);
  if (it == states_->case_models.end())
    it = states_->case_models.emplace(load_case, model_for_case(model_, load_case)).first;
  return it->second;
}

int Runner::listed_static(const std::string& load_case) const {
  for (size_t i = 0; i < study_.analyses.size(); ++i)
    if (study_.analyses[i].type == AnalysisSpec::Type::kStatic &&
        study_.analyses[i].load_case == load_case)
      return static_cast<int>(i);
  return -1;
}

std::string Runner::equilibrium_key(const std::string& load_case, int listed, double time) {
  StaticOptions options = listed >= 0 ? study_.analyses[listed].statics : StaticOptions{};
  if (!std::isnan(time)) options.time = time;
  const std::string key =
      load_case + '\n' + std::to_string(listed) + '\n' + format_number(options.time);
  if (states_->equilibria.count(key)) return key;
  Equilibrium& e = states_->equilibria[key];
  const Model& model = case_model(load_case);
  options.structure_cache = structure_cache();
  options.max_seconds = budget_left(options.max_seconds);
  e.data = std::make_unique<Data>(model);
  e.model = &model;
  e.load_case = load_case;
  e.result = solve_static(model, options, *e.data);
  e.time = options.time;
  return key;
}

void Runner::run_static(int index, AnalysisReport& report) {
  const AnalysisSpec& spec = study_.analyses[index];
  const std::string key = equilibrium_key(spec.load_case, index, kNaN);
  const Equilibrium& e = states_->equilibria.at(key);
  const StaticResult& r = e.result;
  EvaluationStates::Analysis& state = states_->analyses[index];
  state.model = e.model;
  state.equilibrium = key;
  state.time = e.time;
  report.ok = r.ok;
  report.timed_out = r.timed_out;
  report.message = r.message;
  report.wall_seconds = r.wall_seconds;
  report.statics = r;
  // The path, also of a run that did not reach the full loads (its limit load is the finding).
  if (options_.result_tables && !r.path.empty())
    keep_tables(report, {static_path_table(table_prefix(spec), case_model(spec.load_case), r)});
  if (!r.ok) return;
  add_warnings(r.warnings);
  const Model& model = case_model(spec.load_case);
  static_responses(study_, index, model, *e.data, ev_.responses);
  state.ok = true;
  if (!draw(report, [&](std::string* error) {
        return options_.vtk->write_static(spec.name, model, *e.data, error);
      }))
    return;
  if (options_.result_tables)
    keep_tables(report, static_tables(table_prefix(spec), model, *e.data));
}

void Runner::run_modal(int index, AnalysisReport& report) {
  const AnalysisSpec& spec = study_.analyses[index];
  report.about = spec.about_static ? "static" : "initial";
  const Model& model = case_model(spec.load_case);
  EvaluationStates::Analysis& state = states_->analyses[index];
  state.data = std::make_unique<Data>(model);
  Data& data = *state.data;
  ModalOptions options = spec.modal;
  if (spec.about_static) {
    // The static analysis of this load case listed in the study, or one with default options.
    state.equilibrium = equilibrium_key(spec.load_case, listed_static(spec.load_case), kNaN);
    const Equilibrium& e = states_->equilibria.at(state.equilibrium);
    report.statics = e.result;
    if (!e.result.ok) {
      report.timed_out = e.result.timed_out;
      report.message = "no static equilibrium to linearize about: " + e.result.message;
      return;
    }
    data.pose = e.data->pose;
    data.q = e.data->q;
    data.rotation = e.data->rotation;
    options.time = e.time;
  }
  options.max_seconds = budget_left(options.max_seconds);
  options.structure_cache = structure_cache();  // the designs share the ordering of K + mu M
  for (const ResponseSpec& response : study_.responses)
    options.keep_mass = options.keep_mass || (response.analysis == index && response.track);
  if (options_.keep_states) options.guard_modes = kSensitivityGuardModes;
  const ModalResult r = solve_modal(model, options, data);
  report.ok = r.ok;
  report.timed_out = r.timed_out;
  report.shift = r.shift;
  for (const Mode& mode : r.modes) report.noise = std::max(report.noise, mode.noise);
  report.message = r.message;
  report.wall_seconds = r.wall_seconds;
  report.eigensolver = r.solver;
  report.rigid_modes = r.rigid_modes;
  report.modes = static_cast<int>(r.modes.size()) - r.rigid_modes;
  report.asymmetry = r.asymmetry;
  report.nonsymmetric = r.nonsymmetric;
  for (const Mode& mode : r.modes)
    report.effective_mass_captured += effective_mass_fraction(mode, r);
  add_warnings(r.warnings);
  if (!r.ok) return;
  std::vector<std::string> warnings;
  std::vector<int> chosen;
  modal_responses(study_, index, model, r, options_.mode_references, ev_.responses, warnings,
                  &ev_.tracked_shapes, &chosen);
  add_warnings(warnings);
  keep_modes(state, model, options, r, chosen);
  if (!draw(report, [&](std::string* error) {
        return options_.vtk->write_modes(spec.name, model, data, r, error);
      }))
    return;
  if (options_.result_tables) keep_tables(report, modal_tables(table_prefix(spec), model, r));
}

void Runner::run_buckling(int index, AnalysisReport& report) {
  const AnalysisSpec& spec = study_.analyses[index];
  const std::string& c = spec.load_case;
  EvaluationStates::Analysis& state = states_->analyses[index];
  auto [reference_model, scaled_model] = buckling_models(model_, c);
  state.reference = std::make_unique<Model>(std::move(reference_model));
  state.scaled = std::make_unique<Model>(std::move(scaled_model));
  const Model* reference = state.reference.get();
  const Model& scaled = *state.scaled;
  state.data = std::make_unique<Data>(model_);
  Data& data = *state.data;
  BucklingOptions options = spec.buckling;
  state.time = options.time;
  if (!c.empty()) {
    state.equilibrium = equilibrium_key("", listed_static(""), options.time);
    const Equilibrium& e = states_->equilibria.at(state.equilibrium);
    report.statics = e.result;
    if (!e.result.ok) {
      report.timed_out = e.result.timed_out;
      report.message =
          "no static equilibrium under the constant loads (those without a case, and "
          "gravity): " +
          e.result.message;
      return;
    }
    data.pose = e.data->pose;
    data.q = e.data->q;
    data.rotation = e.data->rotation;
  }
  options.max_seconds = budget_left(options.max_seconds);
  if (options_.keep_states) options.guard_modes = kSensitivityGuardModes;
  const BucklingResult r = solve_buckling(*reference, scaled, options, data);
  report.ok = r.ok;
  report.timed_out = r.timed_out;
  report.message = r.message;
  report.wall_seconds = r.wall_seconds;
  report.eigensolver = r.solver;
  report.positive_factors = r.positive_factors;
  for (const BucklingMode& m : r.modes) report.factors.push_back(m.factor);
  add_warnings(r.warnings);
  if (!r.ok) return;
  buckling_responses(study_, index, r, ev_.responses);
  state.ok = true;
  state.shapes.resize(model_.n_dofs, static_cast<Eigen::Index>(r.modes.size() + r.guard.size()));
  Eigen::Index column = 0;
  for (const std::vector<BucklingMode>* list : {&r.modes, &r.guard})
    for (const BucklingMode& mode : *list) {
      state.eigenvalues.push_back(mode.factor);
      state.shapes.col(column++) = mode.shape;
    }
  state.complete = static_cast<int>(r.guard.size()) < options.guard_modes;
  state.response_mode.assign(study_.responses.size(), -1);
  for (size_t k = 0; k < study_.responses.size(); ++k) {
    const ResponseSpec& rs = study_.responses[k];
    if (rs.analysis == index && rs.quantity == ResponseSpec::Quantity::kBucklingFactor &&
        rs.mode <= static_cast<int>(r.modes.size()))
      state.response_mode[k] = rs.mode - 1;
  }
  if (!draw(report, [&](std::string* error) {
        return options_.vtk->write_buckling(spec.name, model_, data, r, error);
      }))
    return;
  if (options_.result_tables) keep_tables(report, buckling_tables(table_prefix(spec), model_, r));
}

void Runner::keep_modes(EvaluationStates::Analysis& state, const Model& model,
                        const ModalOptions& options, const ModalResult& r,
                        const std::vector<int>& chosen) {
  state.ok = true;
  state.model = &model;
  state.time = options.time;
  state.load_factor = options.load_factor;
  state.nonsymmetric = r.nonsymmetric;
  std::vector<int> column(r.modes.size(), -1);
  int n = 0;
  for (size_t m = 0; m < r.modes.size(); ++m)
    if (r.modes[m].kind != Mode::Kind::kRigid) column[m] = n++;
  state.shapes.resize(model.n_dofs, n + static_cast<int>(r.guard.size()));
  for (size_t m = 0; m < r.modes.size(); ++m)
    if (column[m] >= 0) {
      state.eigenvalues.push_back(r.modes[m].eigenvalue);
      state.shapes.col(column[m]) = r.modes[m].shape;
    }
  for (const Mode& mode : r.guard) {
    state.shapes.col(static_cast<Eigen::Index>(state.eigenvalues.size())) = mode.shape;
    state.eigenvalues.push_back(mode.eigenvalue);
  }
  state.complete = static_cast<int>(r.guard.size()) < options.guard_modes;
  state.response_mode.assign(chosen.size(), -1);
  for (size_t k = 0; k < chosen.size(); ++k)
    if (chosen[k] >= 0) state.response_mode[k] = column[chosen[k]];
}

void Runner::keep_tables(AnalysisReport& report, std::vector<ResultTable> tables) {
  for (ResultTable& t : tables) {
    report.tables.push_back(t.file);
    report.result_tables.push_back(std::move(t));
  }
}

void Runner::add_warnings(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings)
    if (!w.empty() && std::find(ev_.warnings.begin(), ev_.warnings.end(), w) == ev_.warnings.end())
      ev_.warnings.push_back(w);
}

}  // namespace evaluation_detail

using evaluation_detail::kNaN;
using evaluation_detail::Runner;

void set_analysis_fault(AnalysisFault fault) { evaluation_detail::analysis_fault = fault; }

Evaluation evaluate(const Study& study, const Model& model, const EvaluationOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  Evaluation ev;
  ev.responses.assign(study.responses.size(), kNaN);
  try {
    for (size_t k = 0; k < study.responses.size(); ++k)
      if (study.responses[k].quantity == ResponseSpec::Quantity::kMass)
        ev.responses[k] = mass_response(model, study.responses[k]);
    Runner runner(study, model, options, ev, start);
    for (size_t i = 0; i < study.analyses.size(); ++i) {
      if (stop_requested()) {
        ev.status = Status::kInterrupted;
        ev.message = "interrupted before the " + std::string(type_name(study.analyses[i].type)) +
                     " analysis \"" + study.analyses[i].name + "\"";
        break;
      }
      if (!runner.run(static_cast<int>(i))) break;
    }
    if (options.keep_states) ev.states = runner.states();
    for (std::string& w : evaluate_expressions(study, ev.responses))
      ev.warnings.push_back(std::move(w));
  } catch (const std::exception& e) {
    ev.status = Status::kFailed;
    ev.message = e.what();
  } catch (...) {
    ev.status = Status::kFailed;
    ev.message = kUnknownException;
  }
  ev.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return ev;
}

}  // namespace beamrail
