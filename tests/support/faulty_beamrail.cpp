// beamrail with faults injected into its analyses (optimizer/run/evaluation.hpp,
// set_analysis_fault), for the tests of what an analysis that throws does to a batch
// (tests/optimizer/mpi_failures_test.cpp). Before each analysis of a design:
// - a side load of -130 N on the first load throws std::runtime_error naming the MPI rank;
// - a side load of -170 N throws an exception of no std::exception type (as muparser's errors
//   are);
// - in a study named "faulty_ranks", every analysis on a rank other than 0 throws
//   std::runtime_error naming the rank (a node whose analyses all fail).
// Otherwise it is the beamrail command.
#include <stdexcept>
#include <string>

#include "optimizer/batch/mpi_job.hpp"
#include "optimizer/cli/cli.hpp"
#include "optimizer/run/evaluation.hpp"

namespace {

struct NotAStdException {};

void inject(const beamrail::Study& study, const beamrail::Model& model, int) {
  const beamrail::MpiJob* job = beamrail::mpi_job();
  const int rank = job ? job->rank() : 0;
  const std::string on = " (on rank " + std::to_string(rank) + ")";
  if (study.name == "faulty_ranks" && rank > 0)
    throw std::runtime_error("injected fault: every analysis on this rank throws" + on);
  if (model.loads.empty()) return;
  const double side = model.loads.front().value.y();
  if (side == -130.0) throw std::runtime_error("injected fault at a load of -130 N" + on);
  if (side == -170.0) throw NotAStdException{};
}

}  // namespace

int main(int argc, char** argv) {
  beamrail::set_analysis_fault(inject);
  return beamrail::beamrail_main(argc, argv);
}
