#include "optimizer/batch/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace beamrail {

std::string progress_line(long done, long total, long failures, const std::string& best,
                          double elapsed_seconds) {
  done = std::max(done, 0L);
  total = std::max(total, done);
  const double elapsed = std::max(elapsed_seconds, 0.0);
  char eta[32] = "-";
  if (done > 0)
    std::snprintf(eta, sizeof eta, "%.1f s",
                  elapsed * static_cast<double>(total - done) / static_cast<double>(done));
  char line[512];
  std::snprintf(line, sizeof line, "%ld/%ld designs, %ld failed, best %s, %.1f s elapsed, ETA %s",
                done, total, failures, best.empty() ? "-" : best.c_str(), elapsed, eta);
  return line;
}

Progress::Progress(long total, bool quiet)
    : total_(total),
      active_(!quiet && ::isatty(STDERR_FILENO)),
      start_(std::chrono::steady_clock::now()),
      last_(start_) {}

Progress::~Progress() { finish(); }

void Progress::finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (printed_) std::fputc('\n', stderr);
  printed_ = false;
  active_ = false;
}

void Progress::set_total(long total) {
  std::lock_guard<std::mutex> lock(mutex_);
  total_ = total;
}

void Progress::update(long done, long failures, const std::string& best) {
  if (!active_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (!active_) return;  // finished meanwhile
  const auto now = std::chrono::steady_clock::now();
  if (done < total_ && now - last_ < std::chrono::milliseconds(200)) return;
  last_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  // "\033[K" (erase to the end of the line, the terminal being one) clears what a longer line
  // before it left.
  std::fprintf(stderr, "\r%s\033[K", progress_line(done, total_, failures, best, elapsed).c_str());
  std::fflush(stderr);
  printed_ = true;
}

}  // namespace beamrail
