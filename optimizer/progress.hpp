// A progress line on stderr for long batches: done/total, failures, best so far, elapsed, ETA.
// Silent with --quiet or when stderr is not a terminal.
#pragma once

#include <chrono>
#include <mutex>
#include <string>

namespace beamrail {

class Progress {
 public:
  Progress(long total, bool quiet);
  ~Progress();
  // Records one finished design (thread-safe). `best` describes the best feasible design so far
  // (empty when none).
  void update(long done, long failures, const std::string& best);
  // Ends the progress line (so that messages start on a line of their own).
  void finish();

 private:
  long total_;
  bool active_;
  std::chrono::steady_clock::time_point start_, last_;
  std::mutex mutex_;
  bool printed_ = false;
};

}  // namespace beamrail
