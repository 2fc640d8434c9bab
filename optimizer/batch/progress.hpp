// A progress line on stderr for long batches: done/total, failures, best so far, elapsed, ETA.
// Silent with --quiet or when stderr is not a terminal.
#pragma once

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>

namespace beamrail {

// The text of the progress line (without the leading carriage return): "12/40 designs, 1 failed,
// best mass 16.32, 3.1 s elapsed, ETA 7.2 s". `done` is never shown above `total` (a total below
// done is raised to it); the ETA is elapsed * (total - done) / done, never negative, and "-"
// (unknown) before the first design; `best` empty shows "best -".
std::string progress_line(long done, long total, long failures, const std::string& best,
                          double elapsed_seconds);

class Progress {
 public:
  Progress(long total, bool quiet);
  ~Progress();
  // Records finished designs (thread-safe). `best` describes the best feasible design so far
  // (empty when none).
  void update(long done, long failures, const std::string& best);
  // Changes the total (thread-safe): an optimization's starts that stop before their design
  // budget is spent lower it.
  void set_total(long total);
  // Ends the progress line (so that messages start on a line of their own).
  void finish();

 private:
  long total_;
  std::atomic<bool> active_;
  std::chrono::steady_clock::time_point start_, last_;
  std::mutex mutex_;
  bool printed_ = false;
};

}  // namespace beamrail
