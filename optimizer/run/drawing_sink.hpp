// Where an evaluation hands what its analyses draw (the deformed scene, mode and buckling shapes,
// a transient's frames) as they are computed: output/vtk_output.hpp's VtkOutput files them as
// ParaView collections. The evaluation itself writes nothing.
#pragma once

#include <string>

#include "core/analysis/buckling_analysis.hpp"
#include "core/analysis/modal_analysis.hpp"
#include "core/model/data.hpp"

namespace beamrail {

class DrawingSink {
 public:
  virtual ~DrawingSink() = default;
  // The undeformed scene and the equilibrium in `deformed`; false with *error when it cannot be
  // kept (the analysis then fails).
  virtual bool write_static(const std::string& analysis, const Model& model, const Data& deformed,
                            std::string* error) = 0;
  // The elastic modes of `result` about the state in `about`.
  virtual bool write_modes(const std::string& analysis, const Model& model, const Data& about,
                           const ModalResult& result, std::string* error) = 0;
  // The buckling shapes of `result` about the reference state in `about`.
  virtual bool write_buckling(const std::string& analysis, const Model& model, const Data& about,
                              const BucklingResult& result, std::string* error) = 0;
  // A transient: begin_series, then frame() per output row (it throws std::runtime_error naming
  // the reason when a frame cannot be kept), then end_series(), also after a failed run.
  virtual bool begin_series(const std::string& analysis, const Model& model,
                            std::string* error) = 0;
  virtual void frame(double t, const Data& data) = 0;
  virtual bool end_series(std::string* error) = 0;
};

}  // namespace beamrail
