#include "core/analysis/deformation_check.hpp"

#include <cmath>
#include <cstdio>

#include "core/model/element_kinematics.hpp"

namespace beamrail {
namespace {

// Largest angle of an element; a cylindrical rail's twist is free, not a deformation.
double largest_angle(const ElementEnds& ends, const Data& data, bool twist_free) {
  const ElementFrames<double> f =
      element_frames(ends, data.pose[ends.body1], data.pose[ends.body2], twist_free);
  const double bending = std::max(std::abs(f.phi(1)), std::abs(f.phi(2)));
  return twist_free ? bending : std::max(bending, std::abs(f.phi(0)));
}

std::string message(const char* kind, const std::string& name, double angle, double t,
                    bool with_time) {
  char text[96];
  if (with_time)
    std::snprintf(text, sizeof text, "|phi| reached %.3g rad at t = %.6g s", angle, t);
  else
    std::snprintf(text, sizeof text, "|phi| = %.3g rad", angle);
  char limit[64];
  std::snprintf(limit, sizeof limit, " (small-angle range: %.2g rad)", kSmallAngleLimit);
  return std::string(kind) + " \"" + name + "\" deforms beyond the small-angle range: " + text +
         limit;
}

}  // namespace

DeformationCheck::DeformationCheck(const Model& model)
    : beams_(model.beams.size()), rails_(model.rails.size()) {}

void DeformationCheck::observe(const Model& model, const Data& data, double t) {
  const auto record = [t](Peak& peak, double angle) {
    if (angle > peak.angle) peak = {angle, t};
  };
  for (size_t i = 0; i < model.beams.size(); ++i)
    record(beams_[i], largest_angle(model.beams[i].ends, data, false));
  for (size_t i = 0; i < model.rails.size(); ++i)
    record(rails_[i],
           largest_angle(model.rails[i].ends, data, model.rails[i].type == RailType::kCylindrical));
}

std::vector<std::string> DeformationCheck::warnings(const Model& model, bool with_time) const {
  std::vector<std::string> out;
  for (size_t i = 0; i < beams_.size(); ++i)
    if (beams_[i].angle > kSmallAngleLimit)
      out.push_back(message("beam", model.beams[i].name, beams_[i].angle, beams_[i].t, with_time));
  for (size_t i = 0; i < rails_.size(); ++i)
    if (rails_[i].angle > kSmallAngleLimit)
      out.push_back(message("rail", model.rails[i].name, rails_[i].angle, rails_[i].t, with_time));
  return out;
}

}  // namespace beamrail
