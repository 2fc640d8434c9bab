// How writing a run's results ended. output/ writes the tables and summary.json and hands this
// back, with what the messages need; it prints nothing and decides no exit status: the command
// line (cli/batch_commands.hpp) prints the messages and maps the outcome to the exit status.
#pragma once

#include <string>
#include <vector>

namespace beamrail {

struct RunOutcome {
  enum class Kind {
    kOk,           // the run succeeded and its results are written
    kFailed,       // the run failed: `message` says why (summary.json too)
    kInterrupted,  // a stop request (`signal`) cut the run short; what it computed is written
    kBadInput,     // the command does not fit the folder's files (`message`): nothing was run
    kWriteError,   // results could not be written: `errors`
  };
  Kind kind = Kind::kOk;
  int signal = 0;  // kInterrupted: the signal of the stop request
  std::string message;
  // The write errors met ("cannot write <file>: <reason>"), in the order they were met: those of
  // kWriteError, or one beside another outcome (a summary that could not be written beside a
  // failed run).
  std::vector<std::string> errors;
};

}  // namespace beamrail
