#include "optimizer/cli/interruption.hpp"

#include <signal.h>

#include "core/analysis/stop_request.hpp"

namespace beamrail {
namespace {

struct sigaction previous_int, previous_term;

// Async-signal-safe: one lock-free atomic store. SA_RESETHAND makes the next signal fatal.
void on_signal(int signal) { request_stop(signal); }

}  // namespace

StopOnSignals::StopOnSignals() {
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND | SA_RESTART;
  sigaction(SIGINT, &action, &previous_int);
  sigaction(SIGTERM, &action, &previous_term);
}

StopOnSignals::~StopOnSignals() {
  sigaction(SIGINT, &previous_int, nullptr);
  sigaction(SIGTERM, &previous_term, nullptr);
}

int interrupted_exit_status(int signal) { return 128 + signal; }

}  // namespace beamrail
