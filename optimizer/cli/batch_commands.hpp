// The design studies `beamrail run` runs: each joins what computes (batch/: the designs evaluated,
// handing results back) and what writes (output/: the tables and summary.json, handing back a
// RunOutcome), then prints the result or why there is none and maps the outcome to the exit
// status (docs/study_files.md "Command line"): 0 success; 1 the run failed or its results could
// not be written; 2 the command does not fit the folder's files (--resume of a table of other
// columns, a --design row the table lacks); 128 + the signal's number when SIGINT or SIGTERM
// stopped the run.
#pragma once

#include <filesystem>

#include "optimizer/batch/run_settings.hpp"
#include "optimizer/output/run_outcome.hpp"
#include "optimizer/output/vtk_design.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {

// samples.csv and summary.json.
int run_sweep(const Study& study, const RunSettings& settings);
// history.csv (derivatives.csv with exact gradients), best.json, best_scene.json, summary.json.
int run_optimize(const Study& study, const RunSettings& settings);
// work_precision.csv and summary.json; each run on stderr as it is measured (unless --quiet).
int run_work_precision(const Study& study, const RunSettings& settings);
// sensitivities.csv and summary.json.
int run_sensitivity(const Study& study, const RunSettings& settings);

// The VTK files of the design chosen (output/vtk_design.hpp) of a design study whose batch has
// run into `output`: the design evaluated again with VTK output into <output>/vtk.
int draw_design(const Study& study, const DesignChoice& choice, const std::filesystem::path& output,
                bool quiet);

// The exit status of an outcome: 0, 1 (kFailed, kWriteError), 2 (kBadInput), 128 + the signal
// (kInterrupted).
int exit_status(const RunOutcome& outcome);

}  // namespace beamrail
