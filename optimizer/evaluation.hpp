// One evaluation of a design: run the study's analyses on a Model, compute its responses, and
// (for single runs) write the full result tables. Failures become a status, never an exception.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/analysis/transient.hpp"
#include "optimizer/study.hpp"

namespace beamrail {

struct AnalysisReport {
  std::string type;   // "transient", ...
  bool ok = false;
  std::string message;
  SolverStats stats;
  double t_end = 0.0;            // transient: time reached [s]
  double energy_initial = 0.0;   // transient: total energy at t = 0 [J]
  double energy_final = 0.0;     // transient: total energy at the last sample [J]
  double energy_max_relative_change = 0.0;  // transient: max |E - E0| / max(|E0|, kinetic+elastic scale)
};

struct Evaluation {
  std::string status = "ok";  // ok | failed | invalid
  std::string message;
  std::vector<double> responses;  // one per study.responses, NaN when not computed
  std::vector<AnalysisReport> analyses;
  std::vector<std::string> warnings;
  double wall_seconds = 0.0;
};

struct EvaluationOptions {
  std::filesystem::path output_directory;  // empty: write no tables (batch evaluations)
};

// Runs every analysis of the study on `model` (the study's own or a design's) and computes the
// responses. Never throws.
Evaluation evaluate(const Study& study, const Model& model, const EvaluationOptions& options);

// Total structural mass: declared body masses plus rho S l of every beam and rail with a density.
double structural_mass(const Model& model);

}  // namespace beamrail
