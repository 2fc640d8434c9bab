// Where an evaluation hands the samples of its transient analyses as they are computed: a time
// series reaches its file while the run lasts, so that a killed run keeps its rows
// (output/result_tables.hpp's TimeseriesFiles writes them). The evaluation itself writes nothing.
#pragma once

#include <string>

#include "core/analysis/transient.hpp"

namespace beamrail {

class TransientSink {
 public:
  virtual ~TransientSink() = default;
  // Before a transient analysis's run, with the name of its table (prefix included); false with
  // *error when its samples cannot be kept (the analysis then fails).
  virtual bool begin(const std::string& file, const Model& model, std::string* error) = 0;
  // One sample; throws std::runtime_error when it cannot be kept (the run then fails).
  virtual void sample(const TransientSample& sample, const Data& data) = 0;
  // After the run, also a failed or interrupted one (its samples are kept); false with *error on
  // any error so far.
  virtual bool end(std::string* error) = 0;
};

}  // namespace beamrail
