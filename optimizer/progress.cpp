#include "optimizer/progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace beamrail {

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

void Progress::update(long done, long failures, const std::string& best) {
  if (!active_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  const auto now = std::chrono::steady_clock::now();
  if (done < total_ && now - last_ < std::chrono::milliseconds(200)) return;
  last_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double eta = done > 0 ? elapsed * static_cast<double>(total_ - done) / done : 0.0;
  std::fprintf(stderr, "\r%ld/%ld designs, %ld failed, best %s, %.1f s elapsed, ETA %.1f s   ",
               done, total_, failures, best.empty() ? "-" : best.c_str(), elapsed, eta);
  std::fflush(stderr);
  printed_ = true;
}

}  // namespace beamrail
