#include "core/analysis/modal_coordinates.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>

#include "core/model/element_kinds.hpp"
#include "core/model/rotation.hpp"

namespace beamrail {

namespace {
constexpr int kD = kDofsPerBody;
constexpr int kS = kStatesPerBody;
}  // namespace

bool floats(const Model& model) {
  if (model.free_bodies.empty() || !model.driven_bodies.empty()) return false;
  bool grounded = false;
  for_each_element(model, [&](auto kind, const auto& e, int) {
    using Kind = decltype(kind);
    grounded = grounded || model.bodies[Kind::body1(e)].fixed || model.bodies[Kind::body2(e)].fixed;
  });
  return !grounded;
}

RigidMotion rigid_motion(const Model& model, const double* y) {
  RigidMotion out;
  double mass = 0.0;
  for (int i = 0; i < model.n_free(); ++i) {
    const double m = model.bodies[model.free_bodies[i]].mass;
    const double* s = y + kS * i;
    mass += m;
    out.centre += m * Vec3(s[0], s[1], s[2]);
    out.velocity += m * Vec3(s[7], s[8], s[9]);
  }
  if (!(mass > 0.0)) return RigidMotion{};
  out.centre /= mass;
  out.velocity /= mass;
  Mat3 inertia = Mat3::Zero();
  Vec3 momentum = Vec3::Zero();
  for (int i = 0; i < model.n_free(); ++i) {
    const Body& body = model.bodies[model.free_bodies[i]];
    const double* s = y + kS * i;
    const Mat3 a = rotation_matrix<double>(Vec4(s[3], s[4], s[5], s[6]));
    const Vec3 r = Vec3(s[0], s[1], s[2]) - out.centre;
    const Mat3 own = a * body.inertia * a.transpose();
    inertia += own - body.mass * skew<double>(r) * skew<double>(r);
    momentum += body.mass * r.cross(Vec3(s[7], s[8], s[9]) - out.velocity) +
                own * (a * Vec3(s[10], s[11], s[12]));
  }
  const Eigen::SelfAdjointEigenSolver<Mat3> eigen(0.5 * (inertia + inertia.transpose()));
  const Vec3 values = eigen.eigenvalues();
  const Vec3 l = eigen.eigenvectors().transpose() * momentum;
  Vec3 w = Vec3::Zero();
  for (int k = 0; k < 3; ++k)
    if (values(k) > 1e-12 * values(2)) w(k) = l(k) / values(k);
  out.angular_velocity = eigen.eigenvectors() * w;
  return out;
}

void ModalCoordinates::set_reference(const double* states, int bodies) {
  c0_.resize(bodies);
  q0_.resize(bodies);
  a0_.resize(bodies);
  orientation_.resize(bodies);
  for (int b = 0; b < bodies; ++b) {
    const double* r = states + kS * b;
    c0_[b] = Vec3(r[0], r[1], r[2]);
    q0_[b] = Vec4(r[3], r[4], r[5], r[6]).normalized();
    a0_[b] = rotation_matrix<double>(q0_[b]);
  }
}

void ModalCoordinates::set_turning_frame(double t0, const RigidMotion& motion) {
  turning_ = true;
  t0_ = t0;
  s0_ = motion.centre;
  velocity_ = motion.velocity;
  omega_ = motion.angular_velocity;
}

Vec4 ModalCoordinates::frame_quaternion(double t) const {
  return quat_from_rotation_vector(omega_ * (t - t0_));
}

Mat3 ModalCoordinates::frame_rotation(double t) const {
  return rotation_matrix<double>(frame_quaternion(t));
}

void ModalCoordinates::offsets(double t, const double* y, ModeBlock& x) const {
  x.resize(kD * static_cast<Eigen::Index>(c0_.size()), 2);
  const Mat3 rt = turning_ ? Mat3(frame_rotation(t).transpose()) : Mat3::Identity();
  const Vec3 s = s0_ + velocity_ * (t - t0_);
  for (size_t b = 0; b < c0_.size(); ++b) {
    const double* y13 = y + kS * b;
    Mat3 a = rotation_matrix<double>(Vec4(y13[3], y13[4], y13[5], y13[6]));
    Vec3 c(y13[0], y13[1], y13[2]), v(y13[7], y13[8], y13[9]);
    Vec3 w = a * Vec3(y13[10], y13[11], y13[12]);  // global
    if (turning_) {
      // In the frame: p = R^T (c - s), v = R^T (v - V) - W x p, A = R^T A, w = R^T w - W.
      const Vec3 p = rt * (c - s);
      c = s0_ + p;
      v = rt * (v - velocity_) - omega_.cross(p);
      a = rt * a;
      w = rt * w - omega_;
    }
    x.block<3, 1>(kD * b, 0) = c - c0_[b];
    x.block<3, 1>(kD * b + 3, 0) = rotation_vector(a * a0_[b].transpose());
    x.block<3, 1>(kD * b, 1) = v;
    x.block<3, 1>(kD * b + 3, 1) = rotation_vector_rate(x.block<3, 1>(kD * b + 3, 0), w);
  }
}

bool ModalCoordinates::states(double t, const ModeBlock& x, double* y, double max_rotation,
                              int* far_body) {
  bool within = true;
  Vec4 qr(1, 0, 0, 0);
  if (turning_) {
    qr = frame_quaternion(t);
    rotation_ = rotation_matrix<double>(qr);
  }
  const Vec3 s = s0_ + velocity_ * (t - t0_);
  for (size_t b = 0; b < c0_.size(); ++b) {
    double* y13 = y + kS * b;
    const Vec3 theta = x.block<3, 1>(kD * b + 3, 0);
    if (max_rotation > 0.0 && within && !(theta.norm() <= max_rotation)) {
      if (far_body) *far_body = static_cast<int>(b);
      within = false;
    }
    Vec4 q = quat_multiply(quat_from_rotation_vector(theta), q0_[b]);
    q /= q.norm();
    const Mat3& a = orientation_[b] = rotation_matrix<double>(q);
    Vec3 c = c0_[b] + x.block<3, 1>(kD * b, 0);
    Vec3 v = x.block<3, 1>(kD * b, 1);
    Vec3 w = angular_velocity(theta, x.block<3, 1>(kD * b + 3, 1));  // global (frame) axes
    if (turning_) {
      // Back to fixed axes: c = s + R p, v = V + R (W x p + v), A = R A, body axes w + A^T W.
      const Vec3 p = c - s0_;
      c = s + rotation_ * p;
      v = velocity_ + rotation_ * (omega_.cross(p) + v);
      w += omega_;
      q = quat_multiply(qr, q);
      q /= q.norm();
    }
    w = a.transpose() * w;  // body axes
    for (int j = 0; j < 3; ++j) {
      y13[j] = c(j);
      y13[7 + j] = v(j);
      y13[10 + j] = w(j);
    }
    for (int j = 0; j < 4; ++j) y13[3 + j] = q(j);
  }
  return within;
}

bool ModalCoordinates::accelerations(const ModeBlock& x, const double* ydot,
                                     Eigen::VectorXd& out) const {
  for (size_t b = 0; b < c0_.size(); ++b) {
    const double* d = ydot + kS * b;
    for (int j = 0; j < kS; ++j)
      if (!std::isfinite(d[j])) return false;
    const Mat3& a = orientation_[b];  // of the quaternion states() wrote, in the frame
    const Vec3 theta = x.block<3, 1>(kD * b + 3, 0), theta_rate = x.block<3, 1>(kD * b + 3, 1);
    Vec3 acceleration(d[7], d[8], d[9]);
    Vec3 angular = a * Vec3(d[10], d[11], d[12]);
    if (turning_) {
      // d2p/dt2 = R^T d2c/dt2 - 2 W x dp/dt - W x (W x p); the frame's angular acceleration
      // A (d omega_body / dt) + w x W, w the angular velocity in the frame.
      const Vec3 p = c0_[b] + x.block<3, 1>(kD * b, 0) - s0_;
      const Vec3 v = x.block<3, 1>(kD * b, 1);
      acceleration = rotation_.transpose() * acceleration - 2.0 * omega_.cross(v) -
                     omega_.cross(omega_.cross(p));
      angular += angular_velocity(theta, theta_rate).cross(omega_);
    }
    out.segment<3>(kD * b) = acceleration;
    out.segment<3>(kD * b + 3) = rotation_vector_acceleration(theta, theta_rate, angular);
  }
  return true;
}

double ModalCoordinates::largest_rotation(const ModeBlock& x) const {
  double largest = 0.0;
  for (size_t b = 0; b < c0_.size(); ++b)
    largest = std::max(largest, x.block<3, 1>(kD * static_cast<Eigen::Index>(b) + 3, 0).norm());
  return largest;
}

}  // namespace beamrail
