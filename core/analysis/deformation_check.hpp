// The range of the element laws (docs/model.md "Range of the law"). The beam and rail laws take
// the relative rotation phi of an element as if it were small. Beams under the energy law measure
// it as the rotation vector, smooth while its angle |phi| < pi (kRotationVectorLimit); the paper
// law and rails as three atan2 angles, smooth only while every |phi_i| < pi/2 (their derivative T
// is singular at a bending angle of pi/2), and repeating where an angle passes pi
// (kElementAngleLimit). element_angle is |phi| or the largest |phi_i| (beam_out_of_range and
// rail_out_of_range in core/model). So:
//  - an element whose angle passes kSmallAngleLimit is reported as a warning (the small-angle law
//    is inaccurate there);
//  - one that passes the limit of its measure (angle_limit) is outside the law's range: the
//    analysis fails and names it (more segments keep each element's rotation small);
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
// Past a warning's edge, the part of an element's angle (distance) that element_margins
// gives as its margin (an angle, a distance): the modal method's steps resolve the swings of
// that size, so that the peak the warning reports is the motion's, not a step's
// (core/analysis/modal_step_bounds.hpp).
inline constexpr double kWarnedMargin = 0.1;

// The first element outside the range of its law in the configuration of data.pose, described
// for the user ("beam \"arm\" turned 3.02 rad ..."), or "" when every element is inside.
// fraction: the part of each element's angle limit beyond which it counts as outside (a lower one
// finds elements near the edge).
std::string element_out_of_range(const Model& model, const Data& data, double fraction = 1.0);

// How near each element (the beams, then the rails) is to the edges of its law's range and of
// its warnings, in the configuration of data.pose:
//  - length [m]: a beam's axial extent; a carriage's distance to its travel's ends, or on a rail
//    without a travel to kRailTravelWarning times its initial distance (beyond it, kWarnedMargin
//    of its distance), and to its min_length while above it (infinity: none);
//  - angle [rad]: the element's angle (element_angle) to the next edge above it, kSmallAngleLimit
//    while below it, else the limit of its measure (angle_limit) and at most kWarnedMargin of
//    the angle.
struct ElementMargins {
  std::vector<double> length, angle;
};
ElementMargins element_margins(const Model& model, const Data& data);

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

  // Records the element angles (element_angle) and rail positions in the configuration of
  // data.pose, reached at time t [s].
  void observe(const Model& model, const Data& data, double t);

  // One warning per element whose angle exceeded kSmallAngleLimit, and per rail whose
  // carriage went beyond kRailTravelWarning times its initial distance (rails without a
  // travel), naming the element, the value and (with_time) when it was reached.
  std::vector<std::string> warnings(const Model& model, bool with_time) const;

 private:
  struct Peak {
    double value = 0.0;  // largest element_angle seen [rad], or |l| / l0 for rail travel
    double t = 0.0;      // when [s]
  };
  std::vector<Peak> beams_, rails_, travel_;
};

}  // namespace beamrail
