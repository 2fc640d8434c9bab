#include "optimizer/evaluation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/analysis/stop_request.hpp"
#include "optimizer/responses.hpp"
#include "optimizer/result_tables.hpp"
#include "optimizer/tables.hpp"
#include "optimizer/trajectory.hpp"

namespace beamrail {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const char* analysis_name(AnalysisSpec::Type type) {
  switch (type) {
    case AnalysisSpec::Type::kStatic:
      return "static";
    case AnalysisSpec::Type::kModal:
      return "modal";
    case AnalysisSpec::Type::kTransient:
      break;
  }
  return "transient";
}

class Runner {
 public:
  Runner(const Study& study, const Model& model, const EvaluationOptions& options, Evaluation& ev,
         std::chrono::steady_clock::time_point start)
      : study_(study),
        model_(model),
        options_(options),
        ev_(ev),
        static_data_(model),
        start_(start) {}

  // Runs one analysis; false when it failed (the evaluation then stops).
  bool run(const AnalysisSpec& spec) {
    AnalysisReport report;
    switch (spec.type) {
      case AnalysisSpec::Type::kStatic:
        report = run_static(spec.statics, true);
        break;
      case AnalysisSpec::Type::kModal:
        report = run_modal(spec);
        break;
      case AnalysisSpec::Type::kTransient:
        report = run_transient_analysis(spec);
        break;
    }
    const bool ok = report.ok;
    if (!ok) {
      ev_.status = report.interrupted ? "interrupted" : report.timed_out ? "timeout" : "failed";
      ev_.message = report.type + " analysis: " + report.message;
    }
    ev_.analyses.push_back(std::move(report));
    return ok;
  }

 private:
  // The static equilibrium, solved once; `listed` when the study asked for the static analysis
  // itself (then its tables are written and its responses computed).
  AnalysisReport run_static(const StaticOptions& options, bool listed) {
    AnalysisReport report;
    report.type = "static";
    if (!static_result_) {
      static_options_ = options;
      static_options_.structure_cache =
          options_.structure_cache ? options_.structure_cache : &structures_;
      static_options_.max_seconds = budget_left(options.max_seconds);
      static_result_ = solve_static(model_, static_options_, static_data_);
    }
    const StaticResult& r = *static_result_;
    report.ok = r.ok;
    report.timed_out = r.timed_out;
    report.message = r.message;
    report.wall_seconds = r.wall_seconds;
    report.statics = r;
    if (!listed || !r.ok) return report;
    add_warnings(r.warnings);
    static_responses(study_, model_, static_data_, ev_.responses);
    if (!options_.output_directory.empty()) {
      std::string error;
      if (!write_static_tables(options_.output_directory, model_, static_data_, &error)) {
        report.ok = false;
        report.message = error;
      }
    }
    return report;
  }

  AnalysisReport run_modal(const AnalysisSpec& spec) {
    AnalysisReport report;
    report.type = "modal";
    report.about = spec.about_static ? "static" : "initial";
    Data data(model_);
    ModalOptions options = spec.modal;
    if (spec.about_static) {
      // The static analysis listed in the study, or one with default options.
      const int listed = find_analysis(study_, AnalysisSpec::Type::kStatic);
      const AnalysisReport equilibrium =
          run_static(listed >= 0 ? study_.analyses[listed].statics : StaticOptions{}, false);
      report.statics = equilibrium.statics;
      if (!equilibrium.ok) {
        report.timed_out = equilibrium.timed_out;
        report.message = "no static equilibrium to linearize about: " + equilibrium.message;
        return report;
      }
      data.pose = static_data_.pose;
      data.q = static_data_.q;
      options.time = static_options_.time;
    }
    options.max_seconds = budget_left(options.max_seconds);
    const ModalResult r = solve_modal(model_, options, data);
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
    add_warnings(r.warnings);
    if (!r.ok) return report;
    modal_responses(study_, r, ev_.responses);
    if (!options_.output_directory.empty()) {
      std::string error;
      if (!write_modal_tables(options_.output_directory, model_, r, &error)) {
        report.ok = false;
        report.message = error;
      }
    }
    return report;
  }

  AnalysisReport run_transient_analysis(const AnalysisSpec& spec) {
    AnalysisReport report;
    report.type = "transient";
    Data data(model_);
    std::vector<std::pair<size_t, PointTracker>> peaks;
    for (size_t k = 0; k < study_.responses.size(); ++k)
      if (study_.responses[k].quantity == ResponseSpec::Quantity::kPeakDisplacement) {
        peaks.emplace_back(k, PointTracker(model_, study_.responses[k]));
        ev_.responses[k] = 0.0;
      }
    TimeseriesWriter table;
    std::string table_error;
    const bool tables = !options_.output_directory.empty();
    if (tables && !table.open(options_.output_directory / "timeseries.csv", model_, &table_error)) {
      report.message = table_error;
      return report;
    }

    Trajectory trajectory = trajectory_of(model_);
    bool first = true;
    double scale = 0.0;
    const auto observer = [&](const TransientSample& s, const Data& d) {
      if (first) report.energy_initial = s.energy(), first = false;
      report.energy_final = s.energy();
      scale = std::max({scale, std::abs(report.energy_initial), s.kinetic + std::abs(s.elastic)});
      if (scale > 0.0)
        report.energy_max_relative_change =
            std::max(report.energy_max_relative_change,
                     std::abs(s.energy() - report.energy_initial) / scale);
      for (auto& [k, t] : peaks)
        ev_.responses[k] = std::max(ev_.responses[k], std::abs(t.value(d)));
      if (tables) table.write(s, d);  // throws when the table cannot be written: the run fails
      if (spec.verify) trajectory.record(s, d);
    };
    const TransientOptions options = budgeted(spec.transient);
    const TransientResult result = run_transient(model_, options, data, observer);
    if (tables) table.commit(&table_error);
    report.ok = result.ok;
    report.timed_out = result.timed_out;
    report.interrupted = result.interrupted;
    report.message = result.message;
    if (result.interrupted)
      report.message = "interrupted at t = " + format_number(result.t_reached) + " s";
    report.stats = result.stats;
    report.integrator = options.integrator.method;
    if (!options.integrator.table.empty()) report.integrator += " " + options.integrator.table;
    report.linear_solver = result.linear_solver;
    report.wall_seconds = result.stats.wall_seconds;
    report.t_reached = result.t_reached;
    add_warnings(result.warnings);
    if (!table_error.empty() && report.message.find(table_error) == std::string::npos) {
      report.message = report.ok ? table_error : report.message + "; " + table_error;
      report.ok = false;
    }
    if (!result.ok)
      for (auto& [k, t] : peaks) ev_.responses[k] = kNaN;  // a partial peak is no peak
    if (report.ok && spec.verify) {
      report.verification = verify(options, trajectory);
      if (stop_requested() && !report.verification->ok) {
        report.ok = false;
        report.interrupted = true;
        report.message = "interrupted in the verification rerun";
      }
    }
    return report;
  }

  // An analysis's own max_seconds (0: none) cut to what is left of the evaluation's budget.
  double budget_left(double own) const {
    if (options_.max_seconds <= 0.0) return own;
    const double used =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double left = std::max(1e-3, options_.max_seconds - used);
    return own > 0.0 ? std::min(own, left) : left;
  }

  // The run's options with max_seconds cut to what is left of the evaluation's budget.
  TransientOptions budgeted(TransientOptions options) {
    options.structure_cache = options_.structure_cache ? options_.structure_cache : &structures_;
    options.max_seconds = budget_left(options.max_seconds);
    return options;
  }

  // Reruns the transient at rtol and atol divided by ten and measures how far the run was from it.
  Verification verify(const TransientOptions& options, const Trajectory& run) {
    Verification v;
    TransientOptions tight = budgeted(options);
    tight.integrator.rtol /= 10.0;
    tight.integrator.atol /= 10.0;
    v.rtol = tight.integrator.rtol;
    v.atol = tight.integrator.atol;
    Data data(model_);
    Trajectory reference = trajectory_of(model_);
    const TransientResult r = run_transient(
        model_, tight, data,
        [&reference](const TransientSample& s, const Data& d) { reference.record(s, d); });
    v.ok = r.ok;
    v.message = r.message;
    v.stats = r.stats;
    v.error = r.ok ? trajectory_error(run, reference) : kNaN;
    return v;
  }

  void add_warnings(const std::vector<std::string>& warnings) {
    for (const std::string& w : warnings)
      if (std::find(ev_.warnings.begin(), ev_.warnings.end(), w) == ev_.warnings.end())
        ev_.warnings.push_back(w);
  }

  const Study& study_;
  const Model& model_;
  const EvaluationOptions& options_;
  Evaluation& ev_;
  Data static_data_;
  StaticOptions static_options_;
  std::optional<StaticResult> static_result_;
  SparseStructureCache structures_;  // when the caller shares none
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

Evaluation evaluate(const Study& study, const Model& model, const EvaluationOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  Evaluation ev;
  ev.responses.assign(study.responses.size(), kNaN);
  try {
    for (size_t k = 0; k < study.responses.size(); ++k)
      if (study.responses[k].quantity == ResponseSpec::Quantity::kMass)
        ev.responses[k] = structural_mass(model);
    Runner runner(study, model, options, ev, start);
    for (const AnalysisSpec& spec : study.analyses) {
      if (stop_requested()) {
        ev.status = "interrupted";
        ev.message =
            "interrupted before the " + std::string(analysis_name(spec.type)) + " analysis";
        break;
      }
      if (!runner.run(spec)) break;
    }
  } catch (const std::exception& e) {
    ev.status = "failed";
    ev.message = e.what();
  }
  ev.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return ev;
}

}  // namespace beamrail
