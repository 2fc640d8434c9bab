#include "core/model/data.hpp"

#include "core/model/rotation.hpp"

namespace beamrail {

Data::Data(const Model& model)
    : pose(model.bodies.size()),
      q(model.bodies.size()),
      w(model.bodies.size()),
      rotation(model.bodies.size(), Vec3::Zero()),
      wrench(model.bodies.size(), Vec6::Zero()),
      rail_floored(model.rails.size(), 0),
      rail_floored_ever(model.rails.size(), 0),
      stiffness(model.pattern.blocks.size(), Mat6::Zero()),
      damping(model.pattern.blocks.size(), Mat6::Zero()) {
  for (size_t i = 0; i < model.bodies.size(); ++i) {
    const Body& b = model.bodies[i];
    q[i] = b.orientation / b.orientation.norm();
    w[i] = b.fixed ? Vec3::Zero() : b.angular_velocity;
    pose[i].u = Vec3::Zero();
    pose[i].A = rotation_matrix<double>(q[i]);
    pose[i].v = b.fixed ? Vec3::Zero() : b.velocity;
    pose[i].omega = pose[i].A * w[i];
  }
}

void set_state(const Model& model, Data& data, const double* y) {
  for (int k = 0; k < model.n_free(); ++k) {
    const int i = model.free_bodies[k];
    const double* s = y + kStatesPerBody * k;
    Pose<double>& p = data.pose[i];
    p.u = Vec3(s[0], s[1], s[2]);
    data.q[i] = Vec4(s[3], s[4], s[5], s[6]);
    p.A = rotation_matrix<double>(data.q[i]);
    p.v = Vec3(s[7], s[8], s[9]);
    data.w[i] = Vec3(s[10], s[11], s[12]);
    p.omega = p.A * data.w[i];
  }
}

void set_driven_poses(const Model& model, Data& data, double t) {
  for (int i : model.driven_bodies) {
    const Body& b = model.bodies[i];
    const PrescribedMotion& m = b.motion;
    Pose<double>& p = data.pose[i];
    p.u = m.velocity * m.velocity_time.integral(t);
    p.v = m.velocity * m.velocity_time(t);
    const Vec4 q0 = b.orientation / b.orientation.norm();
    data.q[i] = quat_multiply(
        quat_from_rotation_vector(m.angular_velocity * m.angular_velocity_time.integral(t)), q0);
    p.A = rotation_matrix<double>(data.q[i]);
    p.omega = m.angular_velocity * m.angular_velocity_time(t);
    data.w[i] = p.A.transpose() * p.omega;
  }
}

void initial_state(const Model& model, double* y) {
  for (int k = 0; k < model.n_free(); ++k) {
    const Body& b = model.bodies[model.free_bodies[k]];
    double* s = y + kStatesPerBody * k;
    const Vec4 q = b.orientation / b.orientation.norm();
    for (int j = 0; j < 3; ++j) {
      s[j] = 0.0;
      s[7 + j] = b.velocity(j);
      s[10 + j] = b.angular_velocity(j);
    }
    for (int j = 0; j < 4; ++j) s[3 + j] = q(j);
  }
}

void initial_state_at(const Model& model, const Data& configuration, double* y) {
  initial_state(model, y);
  for (int k = 0; k < model.n_free(); ++k) {
    const int i = model.free_bodies[k];
    double* s = y + kStatesPerBody * k;
    const Vec4 q = configuration.q[i] / configuration.q[i].norm();
    for (int j = 0; j < 3; ++j) s[j] = configuration.pose[i].u(j);
    for (int j = 0; j < 4; ++j) s[3 + j] = q(j);
  }
}

}  // namespace beamrail
