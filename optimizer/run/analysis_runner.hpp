// What runs a study's analyses for one evaluation (optimizer/run/evaluation.hpp is its
// interface): the static, modal and buckling analyses in optimizer/run/evaluation.cpp, the
// transient ones, their checks and verification reruns in optimizer/run/transient_analysis.cpp.
// Internal to those two files.
#pragma once

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
#include "optimizer/run/evaluation.hpp"
#include "optimizer/run/expressions.hpp"
#include "optimizer/run/number_text.hpp"
#include "optimizer/run/responses.hpp"
#include "optimizer/run/trajectory.hpp"
#include "optimizer/run/transient_checks.hpp"
#include "optimizer/run/verification_rerun.hpp"

namespace beamrail::evaluation_detail {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

class Runner {
 public:
  Runner(const Study& study, const Model& model, const EvaluationOptions& options, Evaluation& ev,
         std::chrono::steady_clock::time_point start)
      : study_(study), model_(model), options_(options), ev_(ev), start_(start) {
    states_->analyses.resize(study.analyses.size());
  }

  std::shared_ptr<const EvaluationStates> states() const { return states_; }

  // Runs analysis `index` of the study; false when it failed (the evaluation then stops).
  bool run(int index);

 private:
  using Equilibrium = EvaluationStates::Equilibrium;

  // The model with the loads of `load_case` (and those without a case): the study's own when
  // every load applies.
  const Model& case_model(const std::string& load_case);

  // The first static analysis of the study with this load case, or -1.
  int listed_static(const std::string& load_case) const;

  // The key of the equilibrium under the loads of `load_case` with the options of static analysis
  // `listed` (or the defaults when -1), at the loads' time `time` (NaN: that of the options),
  // solved once.
  std::string equilibrium_key(const std::string& load_case, int listed, double time);

  Equilibrium& equilibrium(const std::string& load_case, int listed, double time) {
    return states_->equilibria.at(equilibrium_key(load_case, listed, time));
  }

  void run_static(int index, AnalysisReport& report);

  void run_modal(int index, AnalysisReport& report);

  // Buckling of a load case: its loads scaled, the loads without a case and gravity held (the
  // reference is their equilibrium). Without a case: the loads without a case and gravity scaled
  // about the unloaded initial state.
  void run_buckling(int index, AnalysisReport& report);

  void run_transient_analysis(int index, AnalysisReport& report);

  // One run of a transient streamed to its outputs: the time series, the VTK frames, the peak
  // responses and the report's energy figures (energy: the scales its drift is weighed against),
  // its bodies' samples kept in *trajectory when given; *floored: whether a rail reached its
  // min_length. A second call (a refined run) replaces what the first wrote. Nothing, with the
  // analysis failed, when its outputs cannot be begun.
  std::optional<TransientResult> stream_transient(
      const AnalysisSpec& spec, const Model& model, const TransientOptions& options,
      std::vector<std::pair<size_t, PointTracker>>& peaks, AnalysisReport& report,
      EnergyScales& energy, Trajectory* trajectory, bool* floored, std::string* table_error);

  // Whether a verified run found off its tolerance is run again at its verification's tighter
  // tolerances (rtol and atol / 10), its results replacing the run's ("refine", default true;
  // docs/study_files.md "transient"): where its rerun found it more than kDriftTolerance times
  // its tolerance off (the centres or the orientations) and the steps are adaptive, no stop was
  // asked for, and the budget left holds the refined run and its own verification (the run's
  // time and three times the first rerun's; else a warning says it was not refined). Records
  // what the first run was in report.refinement.
  bool refine_transient(const AnalysisSpec& spec, const TransientResult& run,
                        std::chrono::steady_clock::time_point began, AnalysisReport& report,
                        std::vector<std::string>* warnings);

  // The elastic modes of a modal result and the mode each frequency response read (chosen: per
  // response, an index into r.modes or -1).
  static void keep_modes(EvaluationStates::Analysis& state, const Model& model,
                         const ModalOptions& options, const ModalResult& r,
                         const std::vector<int>& chosen);

  static void keep_tables(AnalysisReport& report, std::vector<ResultTable> tables);

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
  TransientOptions budgeted(TransientOptions options);

  // The options of a verification rerun of a run with `options`: rtol and atol divided by ten (a
  // fixed step: half the step, which sets its error, and the same tolerances, which set only the
  // Newton iteration's and may be near the rounding floor already), within `seconds` of budget.
  TransientOptions tighter(const TransientOptions& options, double seconds);

  // Reruns the transient with tighter(options) and measures how far the run was from it (`first`:
  // that rerun, made beside the run). A rerun that
  // repeats the run state for state (its steps did not depend on the tolerances: a mechanism's
  // steps held by its stiff modes' bounds, the same at rtol 1e-6 and 1e-7 on a bob on a joint of
  // compliance 1e-9) measured nothing, and a distance of 0 would claim an exact run: its steps
  // then set its error, as a fixed step's do, and a second rerun with steps at most half the
  // run's mean step (t_end / its steps / 2) measures it.
  Verification rerun_tighter(const Model& model, const TransientOptions& options,
                             std::chrono::steady_clock::time_point began, const Trajectory& run,
                             const SolverStats& run_stats, std::optional<Rerun> first);

  void add_warnings(const std::vector<std::string>& warnings);

  const Study& study_;
  const Model& model_;
  const EvaluationOptions& options_;
  Evaluation& ev_;
  std::shared_ptr<EvaluationStates> states_ = std::make_shared<EvaluationStates>();
  SparseStructureCache structures_;  // when the caller shares none
  std::chrono::steady_clock::time_point start_;
};

}  // namespace beamrail::evaluation_detail
