#include "optimizer/cli/cli.hpp"

int main(int argc, char** argv) { return beamrail::beamrail_main(argc, argv); }
