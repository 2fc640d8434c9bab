#include "optimizer/run/verification_rerun.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/model/data.hpp"

namespace beamrail {

long output_rows(const TransientOptions& options) {
  return 1 + std::max(1L, static_cast<long>(std::ceil(options.t_end / options.output_step - 1e-9)));
}

Rerun rerun(const Model& model, const TransientOptions& tight, const TransientOptions& options) {
  Data data(model);
  Trajectory samples = trajectory_of(model, output_rows(options));
  TransientResult result =
      run_transient(model, tight, data,
                    [&samples](const TransientSample& s, const Data& d) { samples.record(s, d); });
  return Rerun{std::move(result), std::move(samples)};
}

RerunBeside::RerunBeside(const Model& model, TransientOptions tight,
                         const TransientOptions& options)
    : tight_(std::move(tight)) {
  tight_.cancel = &cancel_;
  thread_ = std::thread([this, &model, rows = options] {
    try {
      rerun_ = rerun(model, tight_, rows);
    } catch (...) {
      error_ = std::current_exception();
    }
  });
}

RerunBeside::~RerunBeside() {
  cancel_.store(true, std::memory_order_relaxed);
  if (thread_.joinable()) thread_.join();
}

Rerun RerunBeside::take() {
  thread_.join();
  if (error_) std::rethrow_exception(error_);
  return std::move(rerun_);
}

}  // namespace beamrail
