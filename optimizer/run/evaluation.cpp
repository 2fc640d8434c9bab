#include "optimizer/run/evaluation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>

#include "core/analysis/dense_product.hpp"
#include "core/analysis/sensitivity.hpp"
#include "core/analysis/stop_request.hpp"
#include "optimizer/run/expressions.hpp"
#include "optimizer/run/number_text.hpp"
#include "optimizer/run/responses.hpp"
#include "optimizer/run/trajectory.hpp"
#include "optimizer/run/transient_checks.hpp"
#include "optimizer/run/verification_rerun.hpp"

namespace beamrail {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
AnalysisFault analysis_fault = nullptr;  // set_analysis_fault

class Runner {
 public:
  Runner(const Study& study, const Model& model, const EvaluationOptions& options, Evaluation& ev,
         std::chrono::steady_clock::time_point start)
      : study_(study), model_(model), options_(options), ev_(ev), start_(start) {
    states_->analyses.resize(study.analyses.size());
  }

  std::shared_ptr<const EvaluationStates> states() const { return states_; }

  // Runs analysis `index` of the study; false when it failed (the evaluation then stops).
  bool run(int index) {
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

 private:
  using Equilibrium = EvaluationStates::Equilibrium;

  // The model with the loads of `load_case` (and those without a case): the study's own when
  // every load applies.
  const Model& case_model(const std::string& load_case) {
    bool all = true;
    for (const Load& load : model_.loads) all = all && applies_in_case(load, load_case);
    if (all) return model_;
    auto it = states_->case_models.find(load_case);
    if (it == states_->case_models.end())
      it = states_->case_models.emplace(load_case, model_for_case(model_, load_case)).first;
    return it->second;
  }

  // The first static analysis of the study with this load case, or -1.
  int listed_static(const std::string& load_case) const {
    for (size_t i = 0; i < study_.analyses.size(); ++i)
      if (study_.analyses[i].type == AnalysisSpec::Type::kStatic &&
          study_.analyses[i].load_case == load_case)
        return static_cast<int>(i);
    return -1;
  }

  // The key of the equilibrium under the loads of `load_case` with the options of static analysis
  // `listed` (or the defaults when -1), at the loads' time `time` (NaN: that of the options),
  // solved once.
  std::string equilibrium_key(const std::string& load_case, int listed, double time) {
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

  Equilibrium& equilibrium(const std::string& load_case, int listed, double time) {
    return states_->equilibria.at(equilibrium_key(load_case, listed, time));
  }

  void run_static(int index, AnalysisReport& report) {
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

  void run_modal(int index, AnalysisReport& report) {
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

  // Buckling of a load case: its loads scaled, the loads without a case and gravity held (the
  // reference is their equilibrium). Without a case: the loads without a case and gravity scaled
  // about the unloaded initial state.
  void run_buckling(int index, AnalysisReport& report) {
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

  void run_transient_analysis(int index, AnalysisReport& report) {
    const AnalysisSpec& spec = study_.analyses[index];
    const Model& model = case_model(spec.load_case);
    report.initial = spec.initial_static ? "static" : "scene";
    TransientOptions options = budgeted(spec.transient);
    if (spec.initial_static) {
      // The equilibrium of the loads at t = 0, with the options of the case's static analysis.
      const Equilibrium& e = equilibrium(spec.load_case, listed_static(spec.load_case), 0.0);
      report.statics = e.result;
      if (!e.result.ok) {
        report.timed_out = e.result.timed_out;
        report.message = "no static equilibrium at t = 0 to start from: " + e.result.message;
        return;
      }
      options.initial_state.resize(model.n_states);
      initial_state_at(model, *e.data, options.initial_state.data());
      options.max_seconds = budget_left(spec.transient.max_seconds);
    }
    std::vector<std::pair<size_t, PointTracker>> peaks;
    for (size_t k = 0; k < study_.responses.size(); ++k)
      if (study_.responses[k].quantity == ResponseSpec::Quantity::kPeakDisplacement &&
          study_.responses[k].analysis == index)
        peaks.emplace_back(k, PointTracker(model, study_.responses[k]));
    std::string verification = verification_reason(spec, model, options);
    // auto may yet relinearize or hand a phase to bdf (verified_after_the_run): the trajectory
    // is kept.
    const bool verify = !verification.empty() || may_verify_after_the_run(spec, options);
    // The run, then (refine_transient) at most once more at the verification's tighter
    // tolerances, which replaces it: its outputs, figures and warnings are the report's.
    TransientOptions run_options = options;
    std::vector<std::string> warnings;
    for (;;) {
      warnings.clear();
      // The run's budget (run_options.max_seconds) holds it and its reruns together, by the
      // wall clock: beside the run, a rerun's time overlaps the run's.
      const auto began = std::chrono::steady_clock::now();
      Trajectory trajectory = trajectory_of(model, output_rows(options));
      EnergyScales energy;
      std::string table_error;
      bool floored = false;
      // A rerun known to be due runs beside the run where a core is spare; it is cancelled when
      // the run fails (its destructor).
      std::optional<RerunBeside> beside;
      std::optional<ProductThreads> one;  // the run's products on its own thread meanwhile
      const auto start_beside = [&] {     // its budget: what the run's leaves by the wall clock
        const double left = run_options.max_seconds > 0.0
                                ? std::max(1e-3, run_options.max_seconds - seconds_since(began))
                                : 0.0;
        beside.emplace(model, tighter(run_options, left), options);
        one.emplace(1);
      };
      if (options_.verify_beside && !verification.empty()) start_beside();
      // A rerun that auto's run makes due (verified_after_the_run) starts beside it at the
      // phase that makes it so, not after the run.
      TransientOptions streamed_options = run_options;
      if (options_.verify_beside && verification.empty() && verify)
        streamed_options.phase_started = [&](const MethodPhase& phase) {
          if (!beside && phase_verifies(model, phase)) start_beside();
        };
      std::optional<TransientResult> streamed =
          stream_transient(spec, model, streamed_options, peaks, report, energy,
                           verify ? &trajectory : nullptr, &floored, &table_error);
      one.reset();
      if (!streamed) return;  // its outputs could not be begun (report.message says why)
      const TransientResult& result = *streamed;
      report.ok = result.ok;
      report.timed_out = result.timed_out;
      report.interrupted = result.interrupted;
      report.message = result.message;
      if (result.interrupted)
        report.message = "interrupted at t = " + format_number(result.t_reached) + " s";
      report.stats = result.stats;
      report.integrator = method_name(run_options.integrator.method);
      if (!run_options.integrator.table.empty())
        report.integrator += " " + run_options.integrator.table;
      report.linear_solver = result.linear_solver;
      report.phases = result.phases;
      report.phase_count = result.phase_count;
      // The band integrated: chosen for rtol ("auto", or by auto on a large scene) or given.
      report.max_frequency_hz = result.max_frequency_hz > 0.0
                                    ? result.max_frequency_hz
                                    : run_options.integrator.max_frequency_hz;
      report.axial_force_effect = result.axial_force_effect;
      report.axial_force_time = result.axial_force_time;
      report.axial_force_states = result.axial_force_states;
      report.axial_force_seconds = result.axial_force_seconds;
      report.axial_force_unmeasured = result.axial_force_unmeasured;
      report.wall_seconds = result.stats.wall_seconds;
      report.t_reached = result.t_reached;
      warnings = result.warnings;
      if (!table_error.empty() && report.message.find(table_error) == std::string::npos) {
        report.message = report.ok ? table_error : report.message + "; " + table_error;
        report.ok = false;
      }
      if (!result.ok)
        for (auto& [k, t] : peaks) ev_.responses[k] = kNaN;  // a partial peak is no peak
      // Weighed against the tolerances asked (options), also for a refined run.
      if (report.ok && !(report.max_frequency_hz > 0.0) && !floored)
        warnings.push_back(energy_drift_warning(spec, model, options, report.energy_max_change,
                                                energy, result.stats.steps));
      if (verification.empty())
        verification = verified_after_the_run(spec, model, run_options, result);
      report.verification.reset();
      if (!report.ok || verification.empty()) break;
      report.verification = rerun_tighter(model, run_options, began, trajectory, result.stats,
                                          beside ? beside->take() : std::optional<Rerun>());
      Verification& v = *report.verification;
      v.reason = verification;
      weigh_verification(options, &v);
      if (stop_requested() && !v.ok) {
        report.ok = false;
        report.interrupted = true;
        report.message = "interrupted in the verification rerun";
        break;
      }
      // Its rerun stopped where an element left its law's range, which the run stepped over:
      // the run fails (it warned, status ok, until 2026-12-02); its tables stay written.
      if (std::string failure = verification_out_of_range(v, report.refinement); !failure.empty()) {
        report.ok = false;
        report.message = std::move(failure);
        for (auto& [k, t] : peaks) ev_.responses[k] = kNaN;
        break;
      }
      if (report.refinement || !refine_transient(spec, result, began, report, &warnings)) {
        warnings.push_back(verification_warning(spec, options, v, report.refinement));
        break;
      }
      run_options.integrator.rtol = v.rtol;
      run_options.integrator.atol = v.atol;
      run_options.max_seconds = report.refinement->seconds_left;
    }
    // A refined run that failed (an interruption, a budget it still overran) replaced the run's
    // outputs with its own: say whose failure it was.
    if (report.refinement && !report.ok && !report.verification)
      report.message = "the refined run at rtol " + format_number(run_options.integrator.rtol) +
                       " (the run was found more than 10 times its tolerance off; its outputs "
                       "were begun anew) failed: " +
                       report.message;
    add_warnings(warnings);
  }

  // One run of a transient streamed to its outputs: the time series, the VTK frames, the peak
  // responses and the report's energy figures (energy: the scales its drift is weighed against),
  // its bodies' samples kept in *trajectory when given; *floored: whether a rail reached its
  // min_length. A second call (a refined run) replaces what the first wrote. Nothing, with the
  // analysis failed, when its outputs cannot be begun.
  std::optional<TransientResult> stream_transient(
      const AnalysisSpec& spec, const Model& model, const TransientOptions& options,
      std::vector<std::pair<size_t, PointTracker>>& peaks, AnalysisReport& report,
      EnergyScales& energy, Trajectory* trajectory, bool* floored, std::string* table_error) {
    report.ok = false;
    if (options_.vtk && !options_.vtk->begin_series(spec.name, model, &report.message))
      return std::nullopt;
    TransientSink* const table = options_.timeseries;
    const std::string file = table_file(spec, "timeseries.csv");
    if (table && !table->begin(file, model, table_error)) {
      report.message = *table_error;
      return std::nullopt;
    }
    if (table) report.tables = {file};
    for (auto& [k, t] : peaks) ev_.responses[k] = 0.0;
    report.energy_initial = report.energy_final = report.energy_max_change = 0.0;
    Data data(model);
    bool first = true;
    const auto observer = [&](const TransientSample& s, const Data& d) {
      if (first) report.energy_initial = s.energy(), first = false;
      energy.moving = std::max(energy.moving, s.kinetic + s.elastic);
      energy.terms =
          std::max(energy.terms, std::abs(s.kinetic) + std::abs(s.elastic) + std::abs(s.gravity));
      report.energy_final = s.energy();
      report.energy_max_change =
          std::max(report.energy_max_change, std::abs(s.energy() - report.energy_initial));
      for (auto& [k, t] : peaks)
        ev_.responses[k] = std::max(ev_.responses[k], std::abs(t.value(d)));
      if (table) table->sample(s, d);  // throws when it cannot be kept: the run fails
      if (options_.vtk) options_.vtk->frame(s.t, d);  // throws likewise
      if (trajectory) trajectory->record(s, d);
    };
    TransientResult result = run_transient(model, options, data, observer);
    report.energy_max_relative_change =
        report.energy_initial != 0.0 ? report.energy_max_change / std::abs(report.energy_initial)
                                     : kNaN;
    if (table) table->end(table_error);
    if (options_.vtk && table_error->empty()) options_.vtk->end_series(table_error);
    *floored = rail_floored(data);
    return result;
  }

  // Whether a verified run found off its tolerance is run again at its verification's tighter
  // tolerances (rtol and atol / 10), its results replacing the run's ("refine", default true;
  // docs/study_files.md "transient"): where its rerun found it more than kDriftTolerance times
  // its tolerance off (the centres or the orientations) and the steps are adaptive, no stop was
  // asked for, and the budget left holds the refined run and its own verification (the run's
  // time and three times the first rerun's; else a warning says it was not refined). Records
  // what the first run was in report.refinement.
  bool refine_transient(const AnalysisSpec& spec, const TransientResult& run,
                        std::chrono::steady_clock::time_point began, AnalysisReport& report,
                        std::vector<std::string>* warnings) {
    const Verification& v = *report.verification;
    if (!spec.refine || !v.ok || stop_requested() || spec.transient.integrator.fixed_step > 0.0 ||
        !(v.tolerances > kDriftTolerance || v.rotation_tolerances > kDriftTolerance))
      return false;
    const double used = seconds_since(began);  // the run and its rerun, beside it or after it
    const double own =
        spec.transient.max_seconds > 0.0 ? std::max(1e-3, spec.transient.max_seconds - used) : 0.0;
    const double left = budget_left(own);  // 0: no budget
    // The refined run computes what the rerun did and writes what the run wrote (a run writing
    // 30,001 rows and their VTK frames took 3.0 s, its rerun 0.7 s; its refined run, given three
    // times the rerun, ran out of it and the run's outputs were gone: an adversarial review,
    // 2026-12-01), and its own rerun costs about twice the first: one after the other the run's
    // time and three times the rerun's; beside each other (their times measured so) the longer
    // of the two, at most the run's and the rerun's (a budget counted as their sum refused
    // refinements a run after its rerun made: an adversarial review, 2026-12-01).
    const double ran = run.stats.wall_seconds, reran = v.stats.wall_seconds;
    const double needed = v.beside ? std::max(ran + reran, 2.0 * reran) : ran + 3.0 * reran;
    if (left > 0.0 && left < needed) {
      char text[240];
      std::snprintf(text, sizeof text,
                    "not refined at rtol %.2g: the budget left (%.3g s of max_seconds) is less "
                    "than the %.3g s its refined run and rerun would take (the run took %.3g s, "
                    "its verification rerun %.3g s%s)",
                    v.rtol, left, needed, ran, reran, v.beside ? ", beside it" : "");
      warnings->push_back("transient \"" + spec.name + "\": " + text);
      return false;
    }
    Refinement r;
    r.first_run = v;
    r.first_stats = run.stats;
    r.seconds_left = left;
    report.refinement = r;
    return true;
  }

  // The elastic modes of a modal result and the mode each frequency response read (chosen: per
  // response, an index into r.modes or -1).
  static void keep_modes(EvaluationStates::Analysis& state, const Model& model,
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

  static void keep_tables(AnalysisReport& report, std::vector<ResultTable> tables) {
    for (ResultTable& t : tables) {
      report.tables.push_back(t.file);
      report.result_tables.push_back(std::move(t));
    }
  }

  // Writes the analysis's VTK files when asked for (write(&error)); false, with the analysis
  // failed, when they cannot be written.
  template <class Write>
  bool draw(AnalysisReport& report, Write&& write) {
    if (!options_.vtk) return true;
    std::string error;
    if (write(&error)) return true;
    report.ok = false;
    report.message = error;
    return false;
  }

  static std::string table_prefix(const AnalysisSpec& spec) { return table_file(spec, ""); }

  SparseStructureCache* structure_cache() {
    return options_.structure_cache ? options_.structure_cache : &structures_;
  }

  // An analysis's own max_seconds (0: none) cut to what is left of the evaluation's budget.
  static double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  }

  double budget_left(double own) const {
    if (options_.max_seconds <= 0.0) return own;
    const double left = std::max(1e-3, options_.max_seconds - seconds_since(start_));
    return own > 0.0 ? std::min(own, left) : left;
  }

  // The run's options with max_seconds cut to what is left of the evaluation's budget.
  TransientOptions budgeted(TransientOptions options) {
    options.structure_cache = structure_cache();
    options.max_seconds = budget_left(options.max_seconds);
    return options;
  }

  // The options of a verification rerun of a run with `options`: rtol and atol divided by ten (a
  // fixed step: half the step, which sets its error, and the same tolerances, which set only the
  // Newton iteration's and may be near the rounding floor already), within `seconds` of budget.
  TransientOptions tighter(const TransientOptions& options, double seconds) {
    TransientOptions tight = options;
    tight.max_seconds = seconds;
    tight = budgeted(tight);
    if (tight.integrator.fixed_step > 0.0) {
      tight.integrator.fixed_step /= 2.0;
    } else {
      tight.integrator.rtol /= 10.0;
      tight.integrator.atol /= 10.0;
    }
    return tight;
  }

  // Reruns the transient with tighter(options) and measures how far the run was from it (`first`:
  // that rerun, made beside the run). A rerun that
  // repeats the run state for state (its steps did not depend on the tolerances: a mechanism's
  // steps held by its stiff modes' bounds, the same at rtol 1e-6 and 1e-7 on a bob on a joint of
  // compliance 1e-9) measured nothing, and a distance of 0 would claim an exact run: its steps
  // then set its error, as a fixed step's do, and a second rerun with steps at most half the
  // run's mean step (t_end / its steps / 2) measures it.
  Verification rerun_tighter(const Model& model, const TransientOptions& options,
                             std::chrono::steady_clock::time_point began, const Trajectory& run,
                             const SolverStats& run_stats, std::optional<Rerun> first) {
    Verification v;
    double seconds = 0.0;  // of the reruns so far
    // The run's max_seconds holds the run and its reruns together, from `began` (the run's
    // start) by the wall clock.
    const auto left = [&] {
      return options.max_seconds > 0.0 ? std::max(1e-3, options.max_seconds - seconds_since(began))
                                       : 0.0;
    };
    TransientOptions tight = tighter(options, left());
    v.rtol = tight.integrator.rtol;
    v.atol = tight.integrator.atol;
    v.fixed_step = tight.integrator.fixed_step;
    bool repeated = false;
    v.beside = first.has_value();
    const auto measure = [&] {
      const Rerun r = first ? std::move(*first) : rerun(model, tight, options);
      first.reset();
      seconds += r.result.stats.wall_seconds;
      v.ok = r.result.ok;
      v.message = r.result.message;
      v.out_of_range = r.result.out_of_range;
      v.stats = r.result.stats;
      v.stats.wall_seconds = seconds;  // of the reruns together
      v.error = r.result.ok ? trajectory_error(run, r.samples) : kNaN;
      v.rotation_error = r.result.ok ? trajectory_rotation_error(run, r.samples) : kNaN;
      v.motion = largest_motion(r.samples);
      v.turn = largest_turn(r.samples);
      v.turned = largest_accumulated_turn(r.samples);
      repeated = r.result.ok && same_samples(run, r.samples);
    };
    measure();
    if (repeated && !(tight.integrator.fixed_step > 0.0) && run_stats.steps > 0) {
      const double half = 0.5 * options.t_end / static_cast<double>(run_stats.steps);
      tight.integrator.max_step =
          tight.integrator.max_step > 0.0 ? std::min(tight.integrator.max_step, half) : half;
      tight.max_seconds = budget_left(left());
      v.max_step = tight.integrator.max_step;
      measure();
    }
    if (repeated) {
      v.error = v.rotation_error = kNaN;
      v.message =
          "the reruns gave the same states at every output: the run's error is not measured";
    }
    return v;
  }

  void add_warnings(const std::vector<std::string>& warnings) {
    for (const std::string& w : warnings)
      if (!w.empty() &&
          std::find(ev_.warnings.begin(), ev_.warnings.end(), w) == ev_.warnings.end())
        ev_.warnings.push_back(w);
  }

  const Study& study_;
  const Model& model_;
  const EvaluationOptions& options_;
  Evaluation& ev_;
  std::shared_ptr<EvaluationStates> states_ = std::make_shared<EvaluationStates>();
  SparseStructureCache structures_;  // when the caller shares none
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

void set_analysis_fault(AnalysisFault fault) { analysis_fault = fault; }

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
