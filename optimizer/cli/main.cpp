#include <string>
#include <vector>

#include "optimizer/cli/cli.hpp"

int main(int argc, char** argv) {
  return beamrail::run_command_line(std::vector<std::string>(argv + 1, argv + argc));
}
