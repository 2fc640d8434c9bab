// Deformation beyond the small-angle range: the beam and rail laws (DESIGN.md §1) take the
// relative rotation angles phi of an element as if they were small. An analysis watches the
// largest |phi| of every element over the states it accepts and warns, once per element, when it
// went beyond kSmallAngleLimit.
#pragma once

#include <string>
#include <vector>

#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

inline constexpr double kSmallAngleLimit = 0.5;  // [rad]

class DeformationCheck {
 public:
  explicit DeformationCheck(const Model& model);

  // Records the element angles in the configuration of data.pose, reached at time t [s].
  void observe(const Model& model, const Data& data, double t);

  // One warning per element whose largest |phi| exceeded kSmallAngleLimit, naming the element,
  // the angle and (with_time) when it was reached.
  std::vector<std::string> warnings(const Model& model, bool with_time) const;

 private:
  struct Peak {
    double angle = 0.0;  // largest |phi_i| seen [rad]
    double t = 0.0;      // when [s]
  };
  std::vector<Peak> beams_, rails_;
};

}  // namespace beamrail
