// summary.json (docs/study_files.md "Outputs"): what was modelled, what each analysis cost, the
// responses, the status and the warnings of a run.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "optimizer/output/run_outcome.hpp"
#include "optimizer/run/evaluation.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {

// Counts of what the model holds.
nlohmann::json model_summary(const Model& model);

// The summary of a single evaluation of a study.
nlohmann::json evaluation_summary(const Study& study, const Model& model, const Evaluation& ev);

// A number for JSON output: null when not finite.
nlohmann::json json_number(double x);

// Writes the summary of a batch that failed before its first design (`type`: "sweep",
// "optimize", "sensitivity"): kFailed with `message`, and the error when the summary could not be
// written.
RunOutcome fail_before_designs(const Study& study, const std::filesystem::path& output,
                               const std::string& type, const std::string& message);

}  // namespace beamrail
