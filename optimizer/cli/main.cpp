#include <string>
#include <vector>

#include "optimizer/batch/mpi_job.hpp"
#include "optimizer/cli/cli.hpp"
#include "optimizer/cli/interruption.hpp"

int main(int argc, char** argv) {
  // Under mpirun (or srun) every rank starts here; rank 0 runs the command line, the others
  // evaluate the designs it sends them (optimizer/batch/mpi_job.hpp).
  beamrail::MpiJob job(&argc, &argv);
  if (job.rank() > 0) {
    const beamrail::StopOnSignals signals;
    job.serve();
    return 0;
  }
  return beamrail::run_command_line(std::vector<std::string>(argv + 1, argv + argc));
}
