#include <cstdlib>

#include "optimizer/cli/cli.hpp"

namespace {

// OpenMP's threads wait for work passively unless the environment says otherwise: GNU OpenMP
// reads OMP_WAIT_POLICY once, as it loads, before any constructor of this program runs; the
// executable's .preinit_array runs before that. Spinning, a product team's idle thread held its
// core whenever another process wanted it, and a run with -j 2 beside one other busy process took
// 13 s where -j 1 took 2.2 s (docs/transient_measurements.md "Product threads beside other work").
void wait_passively(int, char**, char**) { setenv("OMP_WAIT_POLICY", "PASSIVE", 0); }

}  // namespace

__attribute__((section(".preinit_array"),
               used)) static void (*const kWaitPassively)(int, char**, char**) = wait_passively;

int main(int argc, char** argv) { return beamrail::beamrail_main(argc, argv); }
