// Settings of one `beamrail run` (command-line options).
#pragma once

#include <filesystem>
#include <string>

namespace beamrail {

struct RunSettings {
  std::filesystem::path output;  // OUTDIR
  int threads = 0;               // 0: all cores
  bool resume = false;           // continue the tables already in OUTDIR
  bool quiet = false;            // no progress line
  std::string command;           // how to run the study again (for "continue with" messages)
};

// The most threads -j may ask for; a batch also never starts more threads than it has designs
// (or gradient points, or starts) to evaluate at once.
inline constexpr int kMaxThreads = 1024;

// The threads a batch of `work` items evaluated at once gets: -j (or all cores), at most `work`,
// at least 1.
int batch_threads(const RunSettings& settings, long work);

}  // namespace beamrail
