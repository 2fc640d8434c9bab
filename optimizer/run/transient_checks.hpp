// Whether a transient's result can be trusted: the checks that make a run say so when it may not
// be (optimizer/run/transient_analysis.cpp runs them after each transient): the energy drift of a
// scene that keeps its energy, and the verification rerun (when a run is verified and what its
// rerun found). Each warning is "" where there is nothing to say.
#pragma once

#include <limits>
#include <optional>
#include <string>

#include "core/analysis/transient.hpp"
#include "core/model/data.hpp"
#include "core/model/model.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {

// A transient rerun at tolerances ten times tighter: the error the run achieved beside its cost.
struct Verification {
  bool ok = false;
  std::string message;
  bool out_of_range = false;      // the tighter run stopped where an element left its range
  double rtol = 0.0, atol = 0.0;  // of the tighter run
  double fixed_step = 0.0;        // of the tighter run (half the run's); 0: adaptive
  // Where the first rerun repeated the run state for state: the second rerun's longest step
  // (half the run's mean step) [s]; 0: none
  double max_step = 0.0;
  double error = 0.0;           // largest body-centre distance between the runs / largest motion
  double rotation_error = 0.0;  // largest angle between the runs' orientations / largest turn
  // The tighter run's largest centre motion [m], largest turn [rad, at most pi] and largest turn
  // along its samples [rad; NaN when its samples may have skipped a turn]: what the errors are
  // measured against.
  double motion = 0.0, turn = 0.0, turned = 0.0;
  // The distances between the runs in multiples of the run's tolerance, as the warning weighs
  // them (weigh_verification): NaN where not measured, and for a fixed step.
  double tolerances = std::numeric_limits<double>::quiet_NaN();
  double rotation_tolerances = std::numeric_limits<double>::quiet_NaN();
  SolverStats stats;    // of the tighter run
  std::string reason;   // why the run was verified: asked, or "verify": "auto"
  bool beside = false;  // the first rerun ran beside the run (EvaluationOptions::verify_beside)
};

// A transient run again at its verification's tighter tolerances, whose results replaced the
// first run's ("refine"): what the first run was.
struct Refinement {
  Verification first_run;     // its verification (rtol, atol: the refined run's)
  SolverStats first_stats;    // the first run's
  double seconds_left = 0.0;  // given to the refined run and its verification [s]; 0: no budget
};

// How far past rtol an energy drift or a verification may go before the run warns: the
// tolerance proportionality auto keeps on its tested scenes is within 10 rtol (README).
inline constexpr double kDriftTolerance = 10.0;

// The largest kinetic + elastic energy of a run's rows (the energy in play) and the largest sum
// of the magnitudes of its three terms (what rounds) [J].
struct EnergyScales {
  double moving = 0.0, terms = 0.0;
};

// Whether a rail reached its min_length in the run (the energy jumps at its law's kink: no drift
// check).
bool rail_floored(const Data& data);

// The warning of a run of a scene that keeps its energy whose energy drifted by more than
// kDriftTolerance rtol of the energy in play (drift and energy: the run's largest change and
// scales; steps: its steps, for the rounding floor).
std::string energy_drift_warning(const AnalysisSpec& spec, const Model& model,
                                 const TransientOptions& options, double drift,
                                 const EnergyScales& energy, long steps);

// Why a transient is verified before its run (summary.json verification.reason), "" when it is
// not: asked, or by default where its scene moves as a mechanism or bdf or adams integrates it.
std::string verification_reason(const AnalysisSpec& spec, const Model& model,
                                const TransientOptions& options);

// Whether a transient that verification_reason does not verify may be verified after its run.
bool may_verify_after_the_run(const AnalysisSpec& spec, const TransientOptions& options);

// Whether a phase of a run that may_verify_after_the_run makes verified_after_the_run verify it:
// a hand-over to bdf or adams (of a scene with free bodies), or a relinearization.
bool phase_verifies(const Model& model, const MethodPhase& phase);

// Why a transient is verified after its run ("" when it is not): an auto run that handed a phase
// to bdf, or that relinearized.
std::string verified_after_the_run(const AnalysisSpec& spec, const Model& model,
                                   const TransientOptions& options, const TransientResult& result);

// Sets v's distances in multiples of the tolerance of the run (options): the warning's measure.
void weigh_verification(const TransientOptions& options, Verification* v);

// The failure of a run whose verification rerun stopped where an element left its law's range
// (v.out_of_range), where the run went through: the run stepped over it, and its results from
// there on are not the model's, which `ok` would promise (README "Guarantees"); no budget helps.
// "" for any other rerun. The analysis's failure names the analysis.
std::string verification_out_of_range(const Verification& v,
                                      const std::optional<Refinement>& refinement);

// The warning of a verification rerun farther from the run than kDriftTolerance times its
// tolerance, or that failed (options: as asked; refinement: what the run replaced, when it was
// refined).
std::string verification_warning(const AnalysisSpec& spec, const TransientOptions& options,
                                 const Verification& v,
                                 const std::optional<Refinement>& refinement = std::nullopt);

}  // namespace beamrail
