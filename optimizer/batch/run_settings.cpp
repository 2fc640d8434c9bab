#include "optimizer/batch/run_settings.hpp"

#include <omp.h>

#include <algorithm>

namespace beamrail {

int batch_threads(const RunSettings& settings, long work) {
  const long wanted = settings.threads > 0 ? settings.threads : omp_get_num_procs();
  return static_cast<int>(std::max(1L, std::min({wanted, work, static_cast<long>(kMaxThreads)})));
}

}  // namespace beamrail
