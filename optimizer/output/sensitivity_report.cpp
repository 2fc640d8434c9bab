#include "optimizer/output/sensitivity_report.hpp"

#include <cmath>

#include "core/analysis/stop_request.hpp"
#include "optimizer/output/summary.hpp"
#include "optimizer/output/tables.hpp"
#include "optimizer/output/version.hpp"
#include "optimizer/run/status.hpp"

namespace beamrail {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

SensitivityReport report_sensitivity(const Study& study, const RunSettings& settings,
                                     const SensitivityResult& result,
                                     std::chrono::steady_clock::time_point start) {
  const DesignStudy& plan = *study.design;
  const std::vector<double>& x = result.x;
  const DesignOutcome& design = result.design;
  const ResponseSensitivities& s = result.derivatives;
  const std::vector<std::vector<double>>& fd = result.differences;
  const std::string& check_failure = result.check_failure;
  const double design_seconds = result.design_seconds, check_seconds = result.check_seconds;
  const size_t nr = study.responses.size(), nv = x.size();
  std::vector<std::string> header{"response", "variable", "value", "derivative"};
  if (plan.sensitivity.check)
    for (const char* c : {"central_difference", "relative_difference"}) header.push_back(c);
  CsvWriter table;
  std::string error;
  double worst = 0.0;
  bool written = table.open(settings.output / "sensitivities.csv", header, &error, true);
  if (written) {
    for (size_t k = 0; k < nr; ++k)
      for (size_t j = 0; j < nv; ++j) {
        const double d = s.ok ? s.jacobian(k, j) : NAN;
        std::vector<std::string> row{study.responses[k].name, plan.variables[j].name,
                                     format_number(design.responses[k]), format_number(d)};
        if (plan.sensitivity.check) {
          const double scale = std::max(std::abs(d), std::abs(fd[k][j]));
          const double rel = scale > 0.0 ? std::abs(d - fd[k][j]) / scale : 0.0;
          if (std::isfinite(rel)) worst = std::max(worst, rel);
          row.push_back(format_number(fd[k][j]));
          row.push_back(format_number(rel));
        }
        table.row(row);
      }
    written = table.commit(&error);
  }

  RunStatus status = RunStatus::kOk;
  std::string message;
  if (design.status != Status::kOk) {
    status = design.status == Status::kInterrupted ? RunStatus::kInterrupted : RunStatus::kFailed;
    message = "the study's design did not evaluate: " + design.message;
  } else if (!s.ok) {
    status = RunStatus::kFailed;
    message = s.message;
  } else if (!check_failure.empty()) {
    status = RunStatus::kFailed;
    message = check_failure;
  } else if (!written) {
    status = RunStatus::kFailed;
    message = error;
  }
  nlohmann::json summary;
  summary["study"] = study.name;
  summary["file"] = study.file;
  summary["beamrail_version"] = kVersion;
  summary["type"] = "sensitivity";
  summary["status"] = run_status_name(status);
  summary["message"] = message;
  std::vector<std::string> warnings = study.input_warnings;
  if (design.warnings > 0) warnings.push_back(design.message);
  warnings.insert(warnings.end(), s.warnings.begin(), s.warnings.end());
  summary["warnings"] = warnings;
  nlohmann::json variables = nlohmann::json::object(), responses = nlohmann::json::object();
  for (size_t j = 0; j < nv; ++j) variables[plan.variables[j].name] = x[j];
  for (size_t k = 0; k < nr; ++k)
    responses[study.responses[k].name] = json_number(design.responses[k]);
  summary["variables"] = variables;
  summary["responses"] = responses;
  summary["design_seconds"] = design_seconds;
  summary["ranks"] = result.ranks;
  summary["threads"] = result.threads;
  if (plan.sensitivity.check) {
    summary["check_seconds"] = check_seconds;
    summary["check_step"] = plan.sensitivity.check_step;
    summary["largest_relative_difference"] = worst;
  }
  SensitivityReport report;
  report.status = status;
  report.warnings = warnings;
  report.largest_relative_difference = worst;
  report.wall_seconds = seconds_since(start);
  summary["wall_seconds"] = report.wall_seconds;
  summary["model"] = model_summary(study.model);
  RunOutcome& outcome = report.outcome;
  outcome.message = message;
  std::string summary_error;
  if (!write_file_atomically(settings.output / "summary.json", summary.dump(2) + "\n",
                             &summary_error)) {
    outcome.kind = RunOutcome::Kind::kWriteError;
    outcome.errors.push_back(summary_error);
  } else if (status == RunStatus::kInterrupted) {
    outcome.kind = RunOutcome::Kind::kInterrupted;
    outcome.signal = stop_requested();
  } else if (status != RunStatus::kOk) {
    outcome.kind = RunOutcome::Kind::kFailed;
  }
  return report;
}

}  // namespace beamrail
