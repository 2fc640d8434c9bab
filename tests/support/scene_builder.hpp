// Scenes built in code for tests: a JSON scene object assembled member by member, then loaded
// (and validated) like a study's scene.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "tests/support/scenes.hpp"

namespace beamrail::testing {

inline Json vec(double x, double y, double z) { return Json::array({x, y, z}); }

// A joint of `type` between bodies b1 and b2 at `point` (global); a revolute joint's "axis" is the
// caller's to add.
inline Json joint(const std::string& name, const std::string& type, const std::string& b1,
                  const std::string& b2, const Vec3& point) {
  return {{"name", name},
          {"type", type},
          {"body1", b1},
          {"body2", b2},
          {"point", vec(point(0), point(1), point(2))}};
}

// A scene built in code; every element lies along global x unless told otherwise.
struct Scene {
  Json j = {{"materials", Json::object()}, {"sections", Json::object()}, {"bodies", Json::array()},
            {"beams", Json::array()},      {"rails", Json::array()},     {"loads", Json::array()}};

  Scene& material(const std::string& name, double e, double g) {
    j["materials"][name] = {{"E", e}, {"G", g}};
    return *this;
  }
  Scene& material(const std::string& name, double e, double g, double density) {
    j["materials"][name] = {{"E", e}, {"G", g}, {"density", density}};
    return *this;
  }
  // A section given by its properties: S, torsion constant Ix, Iy, Iz.
  Scene& custom(const std::string& name, double s, double ix, double iy, double iz) {
    j["sections"][name] = {{"shape", "custom"}, {"S", s}, {"Ix", ix}, {"Iy", iy}, {"Iz", iz}};
    return *this;
  }
  Scene& circle(const std::string& name, double d) {
    j["sections"][name] = {{"shape", "circle"}, {"diameter", d}};
    return *this;
  }
  Scene& square(const std::string& name, double a) {
    j["sections"][name] = {{"shape", "rectangle"}, {"width", a}, {"height", a}};
    return *this;
  }
  Scene& body(const std::string& name, double mass, const Vec3& inertia, const Vec3& position) {
    j["bodies"].push_back({{"name", name},
                           {"mass", mass},
                           {"inertia", vec(inertia(0), inertia(1), inertia(2))},
                           {"position", vec(position(0), position(1), position(2))}});
    return *this;
  }
  Json& last_body() { return j["bodies"].back(); }
  Scene& beam(const std::string& name, const std::string& b1, const std::string& b2, const Vec3& p1,
              const Vec3& p2, const std::string& material, const std::string& section) {
    j["beams"].push_back({{"name", name},
                          {"body1", b1},
                          {"body2", b2},
                          {"point1", vec(p1(0), p1(1), p1(2))},
                          {"point2", vec(p2(0), p2(1), p2(2))},
                          {"point3", vec(p1(0), p1(1) + (p2 - p1).norm(), p1(2))},
                          {"material", material},
                          {"section", section}});
    return *this;
  }
  Json& last_beam() { return j["beams"].back(); }
  // A rail of `type` ("prismatic" or "cylindrical") fixed to b1, its carriage b2 at point p2.
  Scene& rail(const std::string& name, const std::string& type, const std::string& b1,
              const std::string& b2, const Vec3& p1, const Vec3& p2, const std::string& material,
              const std::string& section) {
    beam(name, b1, b2, p1, p2, material, section);
    Json r = j["beams"].back();
    j["beams"].erase(j["beams"].size() - 1);
    r["type"] = type;
    j["rails"].push_back(r);
    return *this;
  }
  Json& last_rail() { return j["rails"].back(); }
  Scene& force(const std::string& body, const Vec3& value) {
    j["loads"].push_back(
        {{"type", "force"}, {"body", body}, {"value", vec(value(0), value(1), value(2))}});
    return *this;
  }
  Scene& torque(const std::string& body, const Vec3& value) {
    j["loads"].push_back(
        {{"type", "torque"}, {"body", body}, {"value", vec(value(0), value(1), value(2))}});
    return *this;
  }
  Model model() const { return scene_from_json(j.dump()); }
};

}  // namespace beamrail::testing
