#include "core/analysis/deformation_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/model/element_kinematics.hpp"

namespace beamrail {
namespace {

ElementFrames<double> frames(const ElementEnds& ends, const Data& data, RotationMeasure measure) {
  return element_frames(ends, data.pose[ends.body1], data.pose[ends.body2], measure);
}

std::string quoted(const char* kind, const std::string& name) {
  return std::string(kind) + " \"" + name + "\"";
}

std::string format(const char* pattern, double a, double b = 0.0, double c = 0.0) {
  char text[200];
  std::snprintf(text, sizeof text, pattern, a, b, c);
  return text;
}

std::string angle_warning(const char* kind, const std::string& name, double angle, double t,
                          bool with_time) {
  return quoted(kind, name) + " deforms beyond the small-angle range: " +
         (with_time ? format("|phi| reached %.3g rad at t = %.6g s", angle, t)
                    : format("|phi| = %.3g rad", angle)) +
         format(" (small-angle range: %.2g rad)", kSmallAngleLimit);
}

}  // namespace

std::string element_out_of_range(const Model& model, const Data& data, double fraction) {
  const auto too_far = [fraction](const ElementFrames<double>& f, RotationMeasure measure) {
    return !(element_angle(f, measure) <= fraction * angle_limit(measure));
  };
  const auto turned = [](RotationMeasure measure) {
    return measure == RotationMeasure::kRotationVector
               ? format(
                     " (the range of the element law ends at %.3g rad: its rotation vector jumps "
                     "to the opposite axis at pi); split it into more segments",
                     kRotationVectorLimit)
               : format(
                     " (the range of the element law ends at %.3g rad: its angles are singular "
                     "at pi/2); split it into more segments",
                     kElementAngleLimit);
  };
  for (const Beam& e : model.beams) {
    const RotationMeasure measure = rotation_measure(e);
    const ElementFrames<double> f = frames(e.ends, data, measure);
    if (too_far(f, measure))
      return quoted("beam", e.name) +
             format(" turned %.3g rad relative to its first end", element_angle(f, measure)) +
             turned(measure);
    if (!(f.xi(0) > 0.0))
      return quoted("beam", e.name) +
             format(
                 " was compressed through zero length (its axial extent is %.3g m of %.3g m): "
                 "it has inverted",
                 f.xi(0), e.ends.length);
  }
  for (const Rail& e : model.rails) {
    const RotationMeasure measure = rotation_measure(e);
    const ElementFrames<double> f = frames(e.ends, data, measure);
    if (too_far(f, measure))
      return quoted("rail", e.name) +
             format(" turned %.3g rad relative to the rail", element_angle(f, measure)) +
             turned(measure);
    if (!(f.xi(0) >= e.travel_min && f.xi(0) <= e.travel_max))
      return quoted("rail", e.name) +
             format(
                 ": the carriage is at %.6g m from point 1, outside the rail's travel [%.6g, "
                 "%.6g] m: it has left the rail",
                 f.xi(0), e.travel_min, e.travel_max);
  }
  return "";
}

ElementMargins element_margins(const Model& model, const Data& data) {
  ElementMargins out;
  const auto angle_margin = [](const ElementFrames<double>& f, RotationMeasure measure) {
    const double angle = element_angle(f, measure);
    return angle < kSmallAngleLimit ? kSmallAngleLimit - angle
                                    : std::min(angle_limit(measure) - angle, kWarnedMargin * angle);
  };
  for (const Beam& e : model.beams) {
    const RotationMeasure measure = rotation_measure(e);
    const ElementFrames<double> f = frames(e.ends, data, measure);
    out.length.push_back(f.xi(0));
    out.angle.push_back(angle_margin(f, measure));
  }
  for (const Rail& e : model.rails) {
    const RotationMeasure measure = rotation_measure(e);
    const ElementFrames<double> f = frames(e.ends, data, measure);
    const double x = f.xi(0);
    double margin = std::numeric_limits<double>::infinity();
    if (std::isfinite(e.travel_min) || std::isfinite(e.travel_max))
      margin = std::min(x - e.travel_min, e.travel_max - x);
    else if (const double m = kRailTravelWarning * e.ends.length - std::abs(x); m > 0.0)
      margin = m;
    else
      margin = kWarnedMargin * std::abs(x);
    if (e.min_length > 0.0 && std::abs(x) > e.min_length)
      margin = std::min(margin, std::abs(x) - e.min_length);
    out.length.push_back(margin);
    out.angle.push_back(angle_margin(f, measure));
  }
  return out;
}

std::string element_turned_beyond(const Model& model, const Data& data, double limit) {
  const auto rotation = [](const ElementFrames<double>& f, bool twist_free) {
    if (twist_free) return std::atan2(Vec3(f.a.col(0)).tail<2>().norm(), f.a(0, 0));
    // angle = atan2(|axial vector|, (trace - 1) / 2) of the relative rotation
    const Vec3 axial(f.a(2, 1) - f.a(1, 2), f.a(0, 2) - f.a(2, 0), f.a(1, 0) - f.a(0, 1));
    return std::atan2(0.5 * axial.norm(), 0.5 * (f.a.trace() - 1.0));
  };
  const auto describe = [limit](const char* kind, const std::string& name, double angle) {
    return quoted(kind, name) +
           format(
               " turned %.3g rad relative to its first end (beyond %.3g rad, near where its "
               "law repeats every 2 pi)",
               angle, limit);
  };
  for (const Beam& e : model.beams)
    if (const double r = rotation(frames(e.ends, data, rotation_measure(e)), false); !(r <= limit))
      return describe("beam", e.name, r);
  for (const Rail& e : model.rails) {
    const bool twist_free = e.type == RailType::kCylindrical;
    if (const double r = rotation(frames(e.ends, data, rotation_measure(e)), twist_free);
        !(r <= limit))
      return describe("rail", e.name, r);
  }
  return "";
}

DeformationCheck::DeformationCheck(const Model& model)
    : beams_(model.beams.size()), rails_(model.rails.size()), travel_(model.rails.size()) {}

void DeformationCheck::observe(const Model& model, const Data& data, double t) {
  const auto record = [t](Peak& peak, double value) {
    if (value > peak.value) peak = {value, t};
  };
  for (size_t i = 0; i < model.beams.size(); ++i) {
    const RotationMeasure measure = rotation_measure(model.beams[i]);
    record(beams_[i], element_angle(frames(model.beams[i].ends, data, measure), measure));
  }
  for (size_t i = 0; i < model.rails.size(); ++i) {
    const Rail& e = model.rails[i];
    const RotationMeasure measure = rotation_measure(e);
    const ElementFrames<double> f = frames(e.ends, data, measure);
    record(rails_[i], element_angle(f, measure));
    record(travel_[i], std::abs(f.xi(0)) / e.ends.length);
  }
}

std::vector<std::string> DeformationCheck::warnings(const Model& model, bool with_time) const {
  std::vector<std::string> out;
  for (size_t i = 0; i < beams_.size(); ++i)
    if (beams_[i].value > kSmallAngleLimit)
      out.push_back(
          angle_warning("beam", model.beams[i].name, beams_[i].value, beams_[i].t, with_time));
  for (size_t i = 0; i < rails_.size(); ++i) {
    const Rail& e = model.rails[i];
    if (rails_[i].value > kSmallAngleLimit)
      out.push_back(angle_warning("rail", e.name, rails_[i].value, rails_[i].t, with_time));
    const bool bounded = std::isfinite(e.travel_min) || std::isfinite(e.travel_max);
    if (!bounded && travel_[i].value > kRailTravelWarning)
      out.push_back(quoted("rail", e.name) + ": the carriage went " +
                    format("%.3g times its initial distance from point 1 (%.3g m)",
                           travel_[i].value, travel_[i].value * e.ends.length) +
                    (with_time ? format(" at t = %.6g s", travel_[i].t) : "") +
                    "; give the rail's \"travel\" to make leaving the rail an error");
  }
  return out;
}

}  // namespace beamrail
