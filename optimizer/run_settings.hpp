// Settings of one `beamrail run` (command-line options).
#pragma once

#include <filesystem>

namespace beamrail {

struct RunSettings {
  std::filesystem::path output;  // OUTDIR
  int threads = 0;               // 0: all cores
  bool resume = false;           // continue the tables already in OUTDIR
  bool quiet = false;            // no progress line
};

}  // namespace beamrail
