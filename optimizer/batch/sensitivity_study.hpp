// Sensitivity studies (docs/study_files.md "Sensitivities"): the derivative of every response with
// respect to every variable at the study's own design -> sensitivities.csv
// (response,variable,value,derivative; with "check": the central difference of the responses and
// the relative difference of the two).
//
// compute_sensitivities() computes; output/sensitivity_report.hpp writes the table and
// summary.json; cli/batch_commands.hpp joins the two, prints and returns the exit status.
#pragma once

#include <string>
#include <vector>

#include "optimizer/batch/run_settings.hpp"
#include "optimizer/run/designs.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {

struct SensitivityResult {
  std::vector<double> x;  // the study's own design
  DesignOutcome design;
  ResponseSensitivities derivatives;
  // With "check": per response, per variable, the central difference (NaN where not computed),
  // and why a check's design did not evaluate ("" when all did).
  std::vector<std::vector<double>> differences;
  std::string check_failure;
  int threads = 1;
  int ranks = 1;  // that evaluated the check's designs (under mpirun, every rank)
  double design_seconds = 0.0, check_seconds = 0.0;
};

// Evaluates the study's own design with its derivatives (the variables in parallel on the threads
// -j gives), and with "check" the designs of the central differences (through the batch
// executor: under mpirun, spread over the ranks).
SensitivityResult compute_sensitivities(const Study& study, const DesignEvaluator& evaluator,
                                        const RunSettings& settings);

}  // namespace beamrail
