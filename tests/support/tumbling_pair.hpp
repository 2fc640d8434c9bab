// A rotating scene for the transient tests: two bodies joined by a 5 mm steel rod, tumbling
// together (spinning at ~2.7 rad/s about their common centre of mass) while body b also swings
// relative to a, so the rod bends and twists by a few hundredths of a radian. The rod's law:
// `formulation`.
#pragma once

#include <cstdio>
#include <string>

#include "core/model/rotation.hpp"

namespace beamrail::testing {

inline std::string vec3(const Vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "[%.17g, %.17g, %.17g]", v(0), v(1), v(2));
  return buf;
}

inline std::string tumbling_pair_scene(const std::string& formulation = "energy") {
  const double ma = 1.0, mb = 2.0;
  const Vec3 ca(0, 0, 0), cb(0.5, 0.05, -0.03);
  const Vec4 qb = Vec4(0.9, 0.1, -0.3, 0.2).normalized();
  const Mat3 ab = rotation_matrix<double>(qb);
  const Vec3 com = (ma * ca + mb * cb) / (ma + mb);
  const Vec3 spin(1.0, 2.0, 1.5), drift(0.3, -0.2, 0.1), swing(0.0, 1.5, -1.5);
  const Vec3 va = drift + spin.cross(ca - com), vb = drift + spin.cross(cb - com);
  const Vec3 wa = spin, wb = ab.transpose() * (spin + swing);
  return R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.1e10}},
    "sections": {"rod": {"shape": "circle", "diameter": 0.005}},
    "bodies": [
      {"name": "a", "mass": 1.0, "inertia": [0.01, 0.02, 0.03], "position": )" +
         vec3(ca) + R"(, "velocity": )" + vec3(va) + R"(, "angular_velocity": )" + vec3(wa) + R"(},
      {"name": "b", "mass": 2.0, "inertia": [0.02, 0.015, 0.025], "position": )" +
         vec3(cb) + R"(, "orientation": [)" + std::to_string(qb(0)) + ", " + std::to_string(qb(1)) +
         ", " + std::to_string(qb(2)) + ", " + std::to_string(qb(3)) + R"(], "velocity": )" +
         vec3(vb) + R"(, "angular_velocity": )" + vec3(wb) + R"(}],
    "beams": [{"name": "ab", "body1": "a", "body2": "b", "point1": [0.1, 0, 0],
               "point2": [0.4, 0.05, -0.03], "point3": [0.1, 1, 0.2], "material": "steel",
               "section": "rod", "formulation": ")" +
         formulation + R"("}]})";
}
}  // namespace beamrail::testing
