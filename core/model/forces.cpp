#include "core/model/forces.hpp"

#include "core/model/element_kinds.hpp"
#include "core/model/element_tangent.hpp"
#include "core/model/wrench_assembly.hpp"

namespace beamrail {
void add_load_wrenches(const Model& model, Data& data, double t, double load_factor) {
  add_load_wrenches(model, data.pose, t, load_factor, data.wrench);
}

void add_load_stiffness(const Model& model, Data& data, double t, double load_factor) {
  // A rotation increment dtheta (A -> exp([dtheta]x) A) turns every vector carried by the body:
  // dV = dtheta x V = -[V]x dtheta.
  for (const Load& load : model.loads) {
    const int k = model.bodies[load.body].free_index;
    if (k < 0) continue;
    const Pose<double>& pose = data.pose[load.body];
    const Vec3 value = load_value(load, pose, t, load_factor);
    Mat6& s = data.stiffness[k];
    if (load.kind == LoadKind::kForce) {
      const Vec3 lever = pose.A * load.offset;
      if (load.follows) {
        // F and R both turn: dF = -[F]x dtheta, d(R x F) = dtheta x (R x F).
        s.block<3, 3>(0, 3) -= skew<double>(value);
        s.block<3, 3>(3, 3) -= skew<double>(lever.cross(value));
      } else {
        // Only the lever turns: d(R x F) = (dtheta x R) x F = [F]x [R]x dtheta.
        s.block<3, 3>(3, 3) += skew<double>(value) * skew<double>(lever);
      }
    } else if (load.follows) {
      s.block<3, 3>(3, 3) -= skew<double>(value);  // dM = -[M]x dtheta
    }
  }
}

bool is_conservative(const Load& load) { return load.kind == LoadKind::kForce && !load.follows; }

bool conserves_energy(const Model& model) {
  if (!model.loads.empty() || !model.driven_bodies.empty()) return false;
  for (const Beam& b : model.beams)
    if (b.damping != 0.0 || b.formulation != Formulation::kEnergy) return false;
  for (const Rail& r : model.rails)
    if (r.damping != 0.0 || r.formulation != Formulation::kEnergy) return false;
  return true;
}

namespace {

// Scatters an element's 12 x 12 derivative into the four pattern blocks of its ends.
void scatter(const std::array<int, 4>& blocks, const Mat12& j, std::vector<Mat6>& out) {
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) {
      const int k = blocks[2 * a + b];
      if (k >= 0) out[k] += j.block<6, 6>(6 * a, 6 * b);
    }
}

}  // namespace

void compute_wrenches(const Model& model, Data& data, double t, double load_factor) {
  for (Vec6& w : data.wrench) w.setZero();
  add_load_wrenches(model, data, t, load_factor);
  bool out = false;
  const double energy =
      add_element_wrenches(model, data.pose, data.wrench, &data.rail_floored, &out);
  for (size_t r = 0; r < model.rails.size(); ++r)
    if (data.rail_floored[r]) data.rail_floored_ever[r] = 1;
  data.elastic_energy = energy;
  data.out_of_range = out;
  ++data.n_wrench_evaluations;
}

void compute_tangent(const Model& model, Data& data, double t, bool with_velocity,
                     double load_factor) {
  for (Mat6& k : data.stiffness) k.setZero();
  if (with_velocity)
    for (Mat6& c : data.damping) c.setZero();

  add_load_stiffness(model, data, t, load_factor);

  // The kind's configuration tangent for undamped elements (the closed form of beams and rails),
  // and for every element when velocities do not matter (static and modal analyses linearize at
  // rest, where damping forces vanish); forward AD through the whole kernel (positions and
  // velocities) for damped elements in motion.
  int ordinal = 0;
  for_each_element(model, [&](auto kind, const auto& e, int) {
    using Kind = decltype(kind);
    const Pose<double>& p1 = data.pose[Kind::body1(e)];
    const Pose<double>& p2 = data.pose[Kind::body2(e)];
    const std::array<int, 4>& blocks = model.pattern.element_blocks[ordinal++];
    if (Kind::damping(e) == 0.0 || !with_velocity) {
      scatter(blocks, Kind::configuration_jacobian(e, p1, p2), data.stiffness);
      return;
    }
    const auto kernel = [&e](const Pose<Ad12>& b1, const Pose<Ad12>& b2, Vec6T<Ad12>& w1,
                             Vec6T<Ad12>& w2) {
      bool floored = false;
      Kind::wrenches(e, b1, b2, w1, w2, &floored, nullptr);
    };
    scatter(blocks, element_jacobian(seed_configuration(p1, 0), seed_configuration(p2, 6), kernel),
            data.stiffness);
    scatter(blocks, element_jacobian(seed_velocity(p1, 0), seed_velocity(p2, 6), kernel),
            data.damping);
  });
  ++data.n_tangent_evaluations;
}

double kinetic_energy(const Model& model, const Data& data) {
  double e = 0.0;
  for (int i : model.free_bodies) {
    const Body& b = model.bodies[i];
    e += 0.5 * b.mass * data.pose[i].v.squaredNorm() + 0.5 * data.w[i].dot(b.inertia * data.w[i]);
  }
  return e;
}

double gravity_energy(const Model& model, const Data& data) {
  double e = 0.0;
  for (int i : model.free_bodies)
    e -= model.bodies[i].mass * model.gravity.dot(centre(model, data, i));
  return e;
}

bool has_damping(const Model& model) {
  bool damped = false;
  for_each_element(model, [&damped](auto kind, const auto& e, int) {
    damped = damped || decltype(kind)::damping(e) > 0.0;
  });
  return damped;
}

}  // namespace beamrail
