// The generalized forces on every body from gravity, the loads and the elements, on any scalar:
// doubles for the analyses (core/model/forces.hpp), hyper-dual numbers for the design
// sensitivities (a model and poses whose numbers carry derivatives).
#pragma once

#include <vector>

#include "core/model/element_kinds.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// The load's force or torque at time t, scaled by load_factor, in global axes in the pose given
// (a follower load's body-axes value turned by pose.A). Zero at load_factor 0 whatever the time
// (a harmonic load has no final value: NaN at t = infinity, which 0 would not cancel).
template <class S>
Vec3T<S> load_value(const LoadT<S>& load, const Pose<S>& pose, double t, double load_factor = 1.0) {
  if (load_factor == 0.0) return Vec3T<S>::Zero();
  const Vec3T<S> value = (load_factor * load.time(t)) * load.value;
  return load.follows ? Vec3T<S>(pose.A * value) : value;
}

// Adds gravity (at the free bodies' centres) and the loads at time t, scaled by load_factor.
template <class S>
void add_load_wrenches(const ModelT<S>& model, const std::vector<Pose<S>>& pose, double t,
                       double load_factor, std::vector<Vec6T<S>>& wrench) {
  for (int i : model.free_bodies)
    wrench[i].template head<3>() += (load_factor * model.bodies[i].mass) * model.gravity;
  for (const LoadT<S>& load : model.loads) {
    const Pose<S>& p = pose[load.body];
    const Vec3T<S> value = load_value(load, p, t, load_factor);
    Vec6T<S>& w = wrench[load.body];
    if (load.kind == LoadKind::kForce) {
      const Vec3T<S> lever = p.A * load.offset;
      w.template head<3>() += value;
      w.template tail<3>() += lever.cross(value);
    } else {
      w.template tail<3>() += value;
    }
  }
}

// Adds the wrenches of every element and returns their strain energy. For doubles, sets
// rail_floored[r] (when given) per rail and *out_of_range when an element left its law's range.
template <class S>
S add_element_wrenches(const ModelT<S>& model, const std::vector<Pose<S>>& pose,
                       std::vector<Vec6T<S>>& wrench, std::vector<char>* rail_floored = nullptr,
                       bool* out_of_range = nullptr) {
  S energy = 0.0;
  for_each_element(model, [&](auto kind, const auto& e, int n) {
    using Kind = decltype(kind);
    const int i1 = Kind::body1(e), i2 = Kind::body2(e);
    bool floored = false;
    energy += Kind::wrenches(e, pose[i1], pose[i2], wrench[i1], wrench[i2], &floored, out_of_range);
    if constexpr (Kind::kFloors)
      if (rail_floored) (*rail_floored)[n] = floored;
  });
  return energy;
}

}  // namespace beamrail
