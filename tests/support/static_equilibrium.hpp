// The equilibrium of a scene by the static analysis, with every body's displacement and rotation
// vector: the extremes tests' view of a static solution.
#pragma once

#include <string>
#include <vector>

#include "core/analysis/static_analysis.hpp"
#include "core/model/rotation.hpp"
#include "tests/support/scene_builder.hpp"

namespace beamrail::testing {

struct Equilibrium {
  StaticResult result;
  Model model;
  std::vector<Vec3> displacement;  // per body
  std::vector<Vec3> rotation;      // rotation vector per body
  Vec3 u(const std::string& body) const { return displacement[body_index(model, body)]; }
  Vec3 r(const std::string& body) const { return rotation[body_index(model, body)]; }
};

inline Equilibrium equilibrium(const Scene& scene, double tolerance = 1e-12) {
  Equilibrium e;
  e.model = scene.model();
  Data data(e.model);
  StaticOptions options;
  options.tolerance = tolerance;
  e.result = solve_static(e.model, options, data);
  for (size_t i = 0; i < e.model.bodies.size(); ++i) {
    e.displacement.push_back(data.pose[i].u);
    e.rotation.push_back(rotation_vector(data.pose[i].A));
  }
  return e;
}

}  // namespace beamrail::testing
