// The wall-clock budget of an analysis (its max_seconds): checked between the steps of the
// analysis, never by interrupting a library call.
#pragma once

#include <chrono>

namespace beamrail {

// Thrown by Deadline::check out of an analysis's inner loops (an eigensolver's iterations), and
// caught by the analysis itself.
struct DeadlinePassed {};

class Deadline {
 public:
  using Clock = std::chrono::steady_clock;
  Deadline() = default;  // none
  // seconds > 0: the budget from `start`; 0 (or less): none.
  Deadline(Clock::time_point start, double seconds)
      : active_(seconds > 0.0),
        end_(start + std::chrono::duration_cast<Clock::duration>(
                         std::chrono::duration<double>(seconds > 0.0 ? seconds : 0.0))) {}
  bool passed() const { return active_ && Clock::now() > end_; }
  void check() const {
    if (passed()) throw DeadlinePassed{};
  }

 private:
  bool active_ = false;
  Clock::time_point end_{};
};

}  // namespace beamrail
