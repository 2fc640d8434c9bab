// A request to stop early, made by a signal handler (SIGINT, SIGTERM) or by any thread, and polled
// by long computations: a transient run ends as "interrupted" at its next right-hand side, keeping
// the samples it delivered; batch loops stop dispatching designs. Setting and reading the request
// are async-signal-safe (a lock-free atomic).
#pragma once

#include <atomic>

namespace beamrail {

namespace detail {
inline std::atomic<int> stop_request_signal{0};
static_assert(std::atomic<int>::is_always_lock_free);
}  // namespace detail

// Requests a stop; `signal` (> 0) names the reason (the signal number, or any positive value).
inline void request_stop(int signal) noexcept {
  detail::stop_request_signal.store(signal, std::memory_order_relaxed);
}

// The signal of the pending request, 0 when none.
inline int stop_requested() noexcept {
  return detail::stop_request_signal.load(std::memory_order_relaxed);
}

// Withdraws the request (tests; a process handles at most one).
inline void clear_stop_request() noexcept {
  detail::stop_request_signal.store(0, std::memory_order_relaxed);
}

}  // namespace beamrail
