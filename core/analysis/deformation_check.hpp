// The range of the element laws (docs/model.md). The beam and rail laws take the relative rotation
// angles phi of an element as if they were small, and measure them as three atan2 angles of the
// relative rotation: the law is smooth only while every |phi_i| < pi/2 (the angles' derivative T
// is singular at a bending angle of pi/2) and jumps where an angle passes pi (kElementAngleLimit,
// beam_out_of_range and rail_out_of_range in core/model). So:
//  - an element whose largest |phi_i| passes kSmallAngleLimit is reported as a warning (the
//    small-angle law is inaccurate there);
//  - one that passes kElementAngleLimit is outside the law's range: the analysis fails and names
//    it (more segments keep each element's rotation small);
//  - a beam compressed through zero length (the axial coordinate of point 2 in the left-end frame
//    reaches 0) has inverted: the analysis fails;
//  - a carriage that leaves its rail's travel has left the rail: the analysis fails; without a
//    travel, a carriage that goes beyond kRailTravelWarning times its initial distance from
//    point 1 is reported as a warning.
#pragma once

#include <string>
#include <vector>

#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

inline constexpr double kSmallAngleLimit = 0.5;     // [rad]
inline constexpr double kRailTravelWarning = 10.0;  // times the initial distance

// The first element outside the range of its law in the configuration of data.pose, described
// for the user ("beam \"arm\" turned 1.62 rad ..."), or "" when every element is inside.
// angle_limit: the rotation that counts as outside (a lower one finds elements near the edge).
std::string element_out_of_range(const Model& model, const Data& data,
                                 double angle_limit = kElementAngleLimit);

// The first element whose relative rotation (the angle of E1^T E2 in [0, pi]; for a cylindrical
// rail, the angle between the rail's axis and the carriage's) exceeds `limit` [rad], described for
// the user, or "". An element's angles phi pass pi, where its law repeats, only through such a
// rotation: an iterative solver that turns no body by more than (pi - limit) / 2 per step and
// checks every step cannot wrap an element unnoticed.
std::string element_turned_beyond(const Model& model, const Data& data, double limit);

// Watches the elements over the states an analysis accepts and words the warnings.
class DeformationCheck {
 public:
  explicit DeformationCheck(const Model& model);

  // Records the element angles and rail positions in the configuration of data.pose, reached at
  // time t [s].
  void observe(const Model& model, const Data& data, double t);

  // One warning per element whose largest |phi| exceeded kSmallAngleLimit, and per rail whose
  // carriage went beyond kRailTravelWarning times its initial distance (rails without a
  // travel), naming the element, the value and (with_time) when it was reached.
  std::vector<std::string> warnings(const Model& model, bool with_time) const;

 private:
  struct Peak {
    double value = 0.0;  // largest |phi_i| seen [rad], or |l| / l0 for rail travel
    double t = 0.0;      // when [s]
  };
  std::vector<Peak> beams_, rails_, travel_;
};

}  // namespace beamrail
