// One evaluation of a design: run the study's analyses on a Model, compute its responses, and
// (for single runs) keep the full result tables as data; it writes no files (output/ does).
// Failures become a status, never an exception.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/static_analysis.hpp"
#include "core/analysis/transient.hpp"
#include "optimizer/run/drawing_sink.hpp"
#include "optimizer/run/responses.hpp"
#include "optimizer/run/result_tables.hpp"
#include "optimizer/run/status.hpp"
#include "optimizer/run/transient_checks.hpp"
#include "optimizer/run/transient_sink.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {

struct AnalysisReport {
  std::string type;                 // "transient", "static", "modal", "buckling"
  std::string name;                 // the analysis's name in the study
  std::string load_case;            // "" when it applies the loads without a case only
  std::vector<std::string> tables;  // its result tables' files (result_tables and time series)
  // static, modal, buckling: its tables (EvaluationOptions::result_tables)
  std::vector<ResultTable> result_tables;
  bool ok = false;
  bool timed_out = false;    // stopped by a max_seconds budget
  bool interrupted = false;  // stopped by a stop request (SIGINT, SIGTERM)
  std::string message;
  double wall_seconds = 0.0;
  // transient
  SolverStats stats;
  std::string integrator;          // method, and table if any
  std::string linear_solver;       // dense | sparse | none
  double t_reached = 0.0;          // [s]
  std::string initial;             // "scene" or "static" (the equilibrium at t = 0)
  double energy_initial = 0.0;     // total energy at t = 0 [J]
  double energy_final = 0.0;       // at the last sample [J]
  double energy_max_change = 0.0;  // max |E - E0| over the samples [J]
  // max |E - E0| / |E0|; NaN when E0 = 0 (a run starting at rest with no energy)
  double energy_max_relative_change = 0.0;
  // What ran when (auto chooses per scene and per phase; the first kMaxRecordedPhases and the last
  // are kept) and how many phases there were.
  std::vector<MethodPhase> phases;
  long phase_count = 0;
  double max_frequency_hz = 0.0;  // the band integrated (0: every mode) [Hz]
  // The elements' own axial forces: the largest relative change of the deformation measured,
  // when [s], over how many states (TransientResult).
  double axial_force_effect = 0.0, axial_force_time = 0.0;
  int axial_force_states = 0, axial_force_unmeasured = 0;
  double axial_force_seconds = 0.0;
  // Of the results reported (a refined run's, when it was refined).
  std::optional<Verification> verification;
  // When the run was found off its tolerance and run again at its verification's tighter
  // tolerances, whose results are the ones reported ("refine").
  std::optional<Refinement> refinement;
  // static (also the equilibrium a modal or buckling analysis is linearized about, or that a
  // transient starts from)
  std::optional<StaticResult> statics;
  // modal
  std::string about;  // "static" or "initial"
  std::string eigensolver;
  int modes = 0, rigid_modes = 0;
  double shift = 0.0;  // of the inverse problem [1/s^2]
  double noise = 0.0;  // largest Mode::noise among the modes found
  double asymmetry = 0.0;
  bool nonsymmetric = false;  // the non-symmetric eigenproblem (non-conservative loads)
  // per direction x .. rz: the effective mass of the modes computed (rigid ones included) over
  // the total; near 1 when the modes computed capture the scene's response to a base motion
  Vec6 effective_mass_captured = Vec6::Zero();
  // buckling (eigensolver above)
  std::vector<double> factors;  // the lowest positive load factors, ascending
  int positive_factors = 0;     // found in all (fewer than asked: the others are infinite)
};

// What an evaluation leaves for its design sensitivities (EvaluationOptions::keep_states): the
// states its analyses reported about, and which mode each response read.
struct EvaluationStates {
  struct Equilibrium {
    StaticResult result;
    std::unique_ptr<Data> data;
    const Model* model = nullptr;  // its load case's model
    std::string load_case;
    double time = 0.0;  // the loads' time
  };
  struct Analysis {
    bool ok = false;
    const Model* model = nullptr;  // the analysis's model (its load case)
    std::string equilibrium;       // key into equilibria; "": a state independent of the design
    std::unique_ptr<Data> data;    // modal, buckling: the state linearized about
    double time = 0.0, load_factor = 1.0;
    // modal: every elastic mode computed (eigenvalues ascending, M-normalized shapes as columns);
    // buckling: every positive factor computed and its shape
    std::vector<double> eigenvalues;
    Eigen::MatrixXd shapes;
    // With the guard's modes (kSensitivityGuardModes, when its sensitivities are wanted) after
    // those asked for; complete: every mode there is (the guard found fewer than it asked).
    bool complete = false;
    bool nonsymmetric = false;
    std::vector<int> response_mode;  // per study response: the column of `shapes` it reads, or -1
    // buckling: the structure with its constant loads, and with the loads to scale
    std::unique_ptr<Model> reference, scaled;
  };
  std::map<std::string, Model> case_models;
  std::map<std::string, Equilibrium> equilibria;
  std::vector<Analysis> analyses;  // one per study analysis
};

// The structure a buckling analysis of `load_case` holds at its reference (its constant loads:
// those without a case and gravity; none when the case is "") and the structure with the loads it
// scales (those of the case; without a case, those without one and gravity).
template <class S>
std::pair<ModelT<S>, ModelT<S>> buckling_models(const ModelT<S>& model,
                                                const std::string& load_case) {
  ModelT<S> reference = load_case.empty() ? with_loads(
                                                model, [](const LoadT<S>&) { return false; }, false)
                                          : model_for_case(model, "");
  ModelT<S> scaled = with_loads(
      model,
      [&](const LoadT<S>& load) {
        return load_case.empty() ? load.load_case.empty() : load.load_case == load_case;
      },
      load_case.empty());
  return {std::move(reference), std::move(scaled)};
}

struct Evaluation {
  Status status = Status::kOk;
  std::string message;
  std::vector<double> responses;  // one per study.responses, NaN when not computed
  std::vector<AnalysisReport> analyses;
  std::vector<std::string> warnings;
  double wall_seconds = 0.0;
  ModeShapes tracked_shapes;  // the shapes of the modes tracked frequency responses read
  std::shared_ptr<const EvaluationStates> states;  // when EvaluationOptions::keep_states
};

struct EvaluationOptions {
  // Keep the tables of static, modal and buckling analyses (AnalysisReport::result_tables);
  // false for batch evaluations.
  bool result_tables = false;
  // Where the samples of transient analyses go as they are computed; nullptr: nowhere.
  TransientSink* timeseries = nullptr;
  // Wall-clock budget of the whole evaluation [s]; 0: none. A transient still running when it is
  // spent stops, and the evaluation's status is "timeout".
  double max_seconds = 0.0;
  // Sparse Jacobian structures shared with other evaluations of the same topology (thread-safe);
  // nullptr: the evaluation's runs share one among themselves only.
  SparseStructureCache* structure_cache = nullptr;
  // The reference shapes of tracked frequency responses (the study's own design); nullptr: they
  // read their mode by number.
  const ModeShapes* mode_references = nullptr;
  // Keep the states the analyses reported about (Evaluation::states), for design sensitivities.
  bool keep_states = false;
  // Where the analyses hand their drawings (optimizer/output/vtk_output.hpp files them as VTK);
  // nullptr: none.
  DrawingSink* vtk = nullptr;
  // A transient's verification rerun known to be due before the run (verification_reason) runs
  // beside it on a second thread, each with one thread for its products: a single run with a
  // core to spare (beamrail run, -j 2 or more, or no -j on a machine of 2 cores or more). The
  // results are the same to the bit either way; false: after it, as in a batch.
  bool verify_beside = false;
};

// Runs every analysis of the study on `model` (the study's own or a design's), in the listed
// order, and computes the responses. Each analysis applies the loads of its load case. A static
// equilibrium a modal or buckling analysis needs is that of the study's static analysis of the
// same load case (solved once and shared), or one with default options. Never throws: whatever an
// analysis throws (a std::exception or not) ends the evaluation as kFailed with its message.
Evaluation evaluate(const Study& study, const Model& model, const EvaluationOptions& options);

// The message of an evaluation ended by an exception of no std::exception type.
inline constexpr const char* kUnknownException =
    "an analysis threw an exception that is not a std::exception";

// A test seam: called before each analysis of every evaluation with the study, the model and the
// analysis's index, it may throw as an analysis that fails by an exception would
// (tests/support/faulty_beamrail.cpp injects faults to test what a throwing analysis does to a
// batch). The beamrail command sets none. Set it before any evaluation starts.
using AnalysisFault = void (*)(const Study& study, const Model& model, int analysis);
void set_analysis_fault(AnalysisFault fault);

}  // namespace beamrail
