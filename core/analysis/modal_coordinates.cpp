#include "core/analysis/modal_coordinates.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <numeric>

#include "core/model/element_kinds.hpp"
#include "core/model/rotation.hpp"

namespace beamrail {

namespace {
constexpr int kD = kDofsPerBody;
constexpr int kS = kStatesPerBody;
}  // namespace

std::vector<std::vector<int>> floating_parts(const Model& model) {
  if (!model.driven_bodies.empty()) return {};
  const int n = static_cast<int>(model.bodies.size());
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  std::vector<char> grounded(n, 0);
  for (int i = 0; i < n; ++i) grounded[i] = model.bodies[i].fixed ? 1 : 0;
  for_each_element(model, [&](auto kind, const auto& e, int) {
    using Kind = decltype(kind);
    const int a = root(Kind::body1(e)), b = root(Kind::body2(e));
    if (a == b) return;
    parent[a] = b;
    grounded[b] = grounded[b] || grounded[a];
  });
  std::vector<std::vector<int>> parts;
  std::vector<int> part_of(n, -1);
  for (int i = 0; i < model.n_free(); ++i) {
    const int r = root(model.free_bodies[i]);
    if (grounded[r]) continue;
    if (part_of[r] < 0) {
      part_of[r] = static_cast<int>(parts.size());
      parts.emplace_back();
    }
    parts[part_of[r]].push_back(i);
  }
  return parts;
}

RigidMotion rigid_motion(const Model& model, const double* y, const std::vector<int>& part) {
  RigidMotion out;
  double mass = 0.0;
  for (int i : part) {
    const Body& body = model.bodies[model.free_bodies[i]];
    const double m = body.mass;
    const double* s = y + kS * i;
    mass += m;
    out.centre += m * (body.position + Vec3(s[0], s[1], s[2]));
    out.velocity += m * Vec3(s[7], s[8], s[9]);
  }
  if (!(mass > 0.0)) return RigidMotion{};
  out.centre /= mass;
  out.velocity /= mass;
  Mat3 inertia = Mat3::Zero();
  Vec3 momentum = Vec3::Zero();
  for (int i : part) {
    const Body& body = model.bodies[model.free_bodies[i]];
    const double* s = y + kS * i;
    const Mat3 a = rotation_matrix<double>(Vec4(s[3], s[4], s[5], s[6]));
    const Vec3 r = body.position + Vec3(s[0], s[1], s[2]) - out.centre;
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

void ModalCoordinates::set_reference(const Model& model, const double* states) {
  const int bodies = model.n_free();
  position_.resize(bodies);
  c0_.resize(bodies);
  q0_.resize(bodies);
  a0_.resize(bodies);
  orientation_.resize(bodies);
  frames_.clear();
  frame_of_.assign(bodies, -1);
  for (int b = 0; b < bodies; ++b) {
    const double* r = states + kS * b;
    position_[b] = model.bodies[model.free_bodies[b]].position;
    c0_[b] = Vec3(r[0], r[1], r[2]);
    q0_[b] = Vec4(r[3], r[4], r[5], r[6]).normalized();
    a0_[b] = rotation_matrix<double>(q0_[b]);
  }
}

void ModalCoordinates::set_turning_frame(double t0, const RigidMotion& motion,
                                         const std::vector<int>& part) {
  Frame f;
  f.t0 = t0;
  f.s0 = motion.centre;
  f.velocity = motion.velocity;
  f.omega = motion.angular_velocity;
  for (int b : part) frame_of_[b] = static_cast<int>(frames_.size());
  frames_.push_back(f);
}

double ModalCoordinates::fastest_frame_rate() const {
  double fastest = 0.0;
  for (const Frame& f : frames_) fastest = std::max(fastest, f.omega.norm());
  return fastest;
}

void ModalCoordinates::Frame::at(double t) {
  q = quat_from_rotation_vector(omega * (t - t0));
  rotation = rotation_matrix<double>(q);
}

void ModalCoordinates::offsets(double t, const double* y, ModeBlock& x) const {
  x.resize(kD * static_cast<Eigen::Index>(c0_.size()), 2);
  std::vector<Frame> frames = frames_;
  for (Frame& f : frames) f.at(t);
  for (size_t b = 0; b < c0_.size(); ++b) {
    const double* y13 = y + kS * b;
    Mat3 a = rotation_matrix<double>(Vec4(y13[3], y13[4], y13[5], y13[6]));
    Vec3 c(y13[0], y13[1], y13[2]), v(y13[7], y13[8], y13[9]);
    Vec3 w = a * Vec3(y13[10], y13[11], y13[12]);  // global
    if (frame_of_[b] >= 0) {
      // In the frame: p = R^T (c - s), v = R^T (v - V) - W x p, A = R^T A, w = R^T w - W.
      const Frame& f = frames[frame_of_[b]];
      const Mat3 rt = f.rotation.transpose();
      const Vec3 p = rt * (position_[b] + c - f.s0 - f.velocity * (t - f.t0));
      c = f.s0 + p - position_[b];
      v = rt * (v - f.velocity) - f.omega.cross(p);
      a = rt * a;
      w = rt * w - f.omega;
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
  for (Frame& f : frames_) f.at(t);
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
    if (frame_of_[b] >= 0) {
      // Back to fixed axes: c = s + R p, v = V + R (W x p + v), A = R A, body axes w + A^T W.
      const Frame& f = frames_[frame_of_[b]];
      const Vec3 p = position_[b] + c - f.s0;
      c = f.s0 + f.velocity * (t - f.t0) + f.rotation * p - position_[b];
      v = f.velocity + f.rotation * (f.omega.cross(p) + v);
      w += f.omega;
      q = quat_multiply(f.q, q);
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
    if (frame_of_[b] >= 0) {
      // d2p/dt2 = R^T d2c/dt2 - 2 W x dp/dt - W x (W x p); the frame's angular acceleration
      // A (d omega_body / dt) + w x W, w the angular velocity in the frame.
      const Frame& f = frames_[frame_of_[b]];
      const Vec3 p = position_[b] + c0_[b] + x.block<3, 1>(kD * b, 0) - f.s0;
      const Vec3 v = x.block<3, 1>(kD * b, 1);
      acceleration = f.rotation.transpose() * acceleration - 2.0 * f.omega.cross(v) -
                     f.omega.cross(f.omega.cross(p));
      angular += angular_velocity(theta, theta_rate).cross(f.omega);
    }
    out.segment<3>(kD * b) = acceleration;
    out.segment<3>(kD * b + 3) = rotation_vector_acceleration(theta, theta_rate, angular);
  }
  return true;
}

void ModalCoordinates::increment_maps(const ModeBlock& x, Eigen::SparseMatrix<double>* map,
                                      Eigen::SparseMatrix<double>* inverse) const {
  std::vector<Eigen::Triplet<double>> forward, backward;
  forward.reserve(18 * c0_.size());
  backward.reserve(18 * c0_.size());
  const auto add = [](std::vector<Eigen::Triplet<double>>& out, Eigen::Index first,
                      const Mat3& block) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) out.emplace_back(first + i, first + j, block(i, j));
  };
  for (size_t b = 0; b < c0_.size(); ++b) {
    const Eigen::Index first = kD * static_cast<Eigen::Index>(b);
    const Vec3 theta = x.block<3, 1>(first + 3, 0);
    Mat3 jacobian;
    for (int j = 0; j < 3; ++j) jacobian.col(j) = angular_velocity(theta, Vec3::Unit(j));
    const Mat3 frame = frame_of_[b] >= 0 ? frames_[frame_of_[b]].rotation : Mat3::Identity();
    add(forward, first, frame);
    add(forward, first + 3, frame * jacobian);
    add(backward, first, frame.transpose());
    add(backward, first + 3, jacobian.inverse() * frame.transpose());
  }
  const Eigen::Index n = kD * static_cast<Eigen::Index>(c0_.size());
  map->resize(n, n);
  map->setFromTriplets(forward.begin(), forward.end());
  inverse->resize(n, n);
  inverse->setFromTriplets(backward.begin(), backward.end());
}

double ModalCoordinates::largest_rotation(const ModeBlock& x) const {
  double largest = 0.0;
  for (size_t b = 0; b < c0_.size(); ++b)
    largest = std::max(largest, x.block<3, 1>(kD * static_cast<Eigen::Index>(b) + 3, 0).norm());
  return largest;
}

}  // namespace beamrail
