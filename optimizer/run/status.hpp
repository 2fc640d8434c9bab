// How an evaluation ended, as a type (Ceres' TerminationType is the model): every evaluation
// carries a Status and, beside it, a message saying why it is not kOk.
#pragma once

#include <csignal>
#include <optional>
#include <ostream>
#include <string>

namespace beamrail {

enum class Status {
  kOk,           // every analysis ran and every response it could give was computed
  kFailed,       // an analysis failed (no convergence, a singular structure, a write error)
  kTimeout,      // a max_seconds budget was spent before the analyses ended
  kInvalid,      // the design's values break the study (a negative thickness, ...)
  kInterrupted,  // a stop request (SIGINT, SIGTERM) cut it short: not a result
};

// The name used in the tables and in summary.json: "ok", "failed", "timeout", "invalid",
// "interrupted".
inline const char* status_name(Status status) {
  switch (status) {
    case Status::kOk:
      return "ok";
    case Status::kFailed:
      return "failed";
    case Status::kTimeout:
      return "timeout";
    case Status::kInvalid:
      return "invalid";
    case Status::kInterrupted:
      return "interrupted";
  }
  return status_name(Status::kFailed);  // not reached: every Status is named above
}

// The status named `name` (a table read back), nullopt for any other text.
inline std::optional<Status> status_from_name(const std::string& name) {
  for (Status s :
       {Status::kOk, Status::kFailed, Status::kTimeout, Status::kInvalid, Status::kInterrupted})
    if (name == status_name(s)) return s;
  return std::nullopt;
}

// How a whole run ended, as summary.json's "status" says (docs/study_files.md "Outputs"): as an
// evaluation ends (ok, failed, interrupted), or an optimization that found no feasible design, or
// still under way (the marker a run writes into its folder when it starts, replaced by its own
// summary at its end).
enum class RunStatus { kOk, kFailed, kInterrupted, kInfeasible, kRunning };

// The name in summary.json: "ok", "failed", "interrupted" (as status_name), "infeasible",
// "running".
inline const char* run_status_name(RunStatus status) {
  switch (status) {
    case RunStatus::kOk:
      return status_name(Status::kOk);
    case RunStatus::kFailed:
      return status_name(Status::kFailed);
    case RunStatus::kInterrupted:
      return status_name(Status::kInterrupted);
    case RunStatus::kInfeasible:
      return "infeasible";
    case RunStatus::kRunning:
      return "running";
  }
  return status_name(Status::kFailed);
}

// The name of the signal a stop request carries (core/analysis/stop_request.hpp), as summary.json
// and the messages say it: "SIGINT", "SIGTERM" (or "signal N").
inline std::string signal_name(int signal) {
  if (signal == SIGINT) return "SIGINT";
  if (signal == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(signal);
}

// Prints the name (test failure messages).
inline std::ostream& operator<<(std::ostream& out, Status status) {
  return out << status_name(status);
}

}  // namespace beamrail
