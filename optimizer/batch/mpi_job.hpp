// A beamrail run spread over the ranks of an MPI job (`mpirun -n R beamrail run ...`, or a
// cluster's `srun`). Every rank starts the same command; rank 0 alone reads the command line,
// reads and writes files and prints; it sends the study (as read, its scene inlined) to the other
// ranks, and then hands designs out to them one at a time, keeping each rank `threads` + 1
// designs ahead, while evaluating designs with its own threads. The other ranks only evaluate
// the designs they are sent and send the outcomes back; they never touch the results folder.
// Outside an MPI launcher, or in a build without MPI, a process is a job of one rank and MPI is
// never initialized.
#pragma once

#include <memory>

namespace beamrail {

class BatchExecutor;

class MpiJob {
 public:
  // Joins the MPI job when the environment shows that an MPI launcher started this process
  // (OMPI_COMM_WORLD_SIZE, PMIX_RANK or PMI_RANK is set, and the build has MPI).
  MpiJob(int* argc, char*** argv);
  // Rank 0 tells the other ranks to stop; then every rank leaves MPI.
  ~MpiJob();
  MpiJob(const MpiJob&) = delete;
  MpiJob& operator=(const MpiJob&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }

  // Ranks other than 0: evaluates what rank 0 sends until it says stop. Returns the exit status:
  // 0 (a design that fails is an outcome sent back, not an error of the rank).
  int serve();

  // Rank 0: an executor over every rank of the job, each evaluating `threads` designs at once.
  std::unique_ptr<BatchExecutor> executor(int threads);

  // Rank 0: whether the study has been sent to the other ranks (it is sent once, with the first
  // batch; every batch of the run evaluates the same study).
  bool study_sent = false;

 private:
  int rank_ = 0;
  int size_ = 1;
  bool initialized_ = false;
};

// The job of this process while main's MpiJob lives; nullptr before and after, and in tests.
MpiJob* mpi_job();

// Whether this build can join MPI jobs.
bool mpi_available();

}  // namespace beamrail
