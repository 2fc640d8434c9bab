// How an evaluation ended, as a type (Ceres' TerminationType is the model): every evaluation
// carries a Status and, beside it, a message saying why it is not kOk.
#pragma once

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
  return "failed";
}

// The status named `name` (a table read back), nullopt for any other text.
inline std::optional<Status> status_from_name(const std::string& name) {
  for (Status s :
       {Status::kOk, Status::kFailed, Status::kTimeout, Status::kInvalid, Status::kInterrupted})
    if (name == status_name(s)) return s;
  return std::nullopt;
}

// Prints the name (test failure messages).
inline std::ostream& operator<<(std::ostream& out, Status status) {
  return out << status_name(status);
}

}  // namespace beamrail
