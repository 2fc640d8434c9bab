// The beamrail command line (docs/study_files.md "Command line").
#pragma once

#include <string>
#include <vector>

namespace beamrail {

// Runs the command line with arguments args (without the program name). Returns the exit status:
// 0 success, 1 a run failed or its results could not be written, 2 bad input or usage, 128 + the
// signal's number when SIGINT or SIGTERM interrupted the run. Never throws.
int run_command_line(const std::vector<std::string>& args);

// The whole process (main's body): joins the MPI job when an MPI launcher started it; rank 0 runs
// the command line, the other ranks evaluate what rank 0 sends them. Returns the exit status.
int beamrail_main(int argc, char** argv);

}  // namespace beamrail
