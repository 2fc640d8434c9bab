// SIGINT and SIGTERM during a run: the first one requests a stop (core/analysis/stop_request.hpp),
// so that the run ends cleanly: batch loops dispatch no more designs, a running transient stops at
// its next right-hand side, the rows already computed are kept and flushed, and the run says what
// it kept and exits with 128 + the signal's number (130 for SIGINT, 143 for SIGTERM). A second
// signal ends the process at once, as without this handling.
#pragma once

namespace beamrail {

class StopOnSignals {
 public:
  StopOnSignals();   // installs the handlers
  ~StopOnSignals();  // restores the previous ones
  StopOnSignals(const StopOnSignals&) = delete;
  StopOnSignals& operator=(const StopOnSignals&) = delete;
};

// The exit status of a run stopped by `signal`: 128 + signal.
int interrupted_exit_status(int signal);

}  // namespace beamrail
