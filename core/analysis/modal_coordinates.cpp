#include "core/analysis/modal_coordinates.hpp"

#include <algorithm>

#include "core/model/rotation.hpp"

namespace beamrail {

namespace {
constexpr int kD = kDofsPerBody;
constexpr int kS = kStatesPerBody;
}  // namespace

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

void ModalCoordinates::offsets(const double* y, ModeBlock& x) const {
  x.resize(kD * static_cast<Eigen::Index>(c0_.size()), 2);
  for (size_t b = 0; b < c0_.size(); ++b) {
    const double* s = y + kS * b;
    const Mat3 a = rotation_matrix<double>(Vec4(s[3], s[4], s[5], s[6]));
    x.block<3, 1>(kD * b, 0) = Vec3(s[0], s[1], s[2]) - c0_[b];
    x.block<3, 1>(kD * b + 3, 0) = rotation_vector(a * a0_[b].transpose());
    x.block<3, 1>(kD * b, 1) = Vec3(s[7], s[8], s[9]);
    x.block<3, 1>(kD * b + 3, 1) =
        rotation_vector_rate(x.block<3, 1>(kD * b + 3, 0), a * Vec3(s[10], s[11], s[12]));
  }
}

bool ModalCoordinates::states(const ModeBlock& x, double* y, double max_rotation, int* far_body) {
  bool within = true;
  for (size_t b = 0; b < c0_.size(); ++b) {
    double* s = y + kS * b;
    const Vec3 theta = x.block<3, 1>(kD * b + 3, 0);
    if (max_rotation > 0.0 && within && !(theta.norm() <= max_rotation)) {
      if (far_body) *far_body = static_cast<int>(b);
      within = false;
    }
    Vec4 q = quat_multiply(quat_from_rotation_vector(theta), q0_[b]);
    q /= q.norm();
    const Mat3& a = orientation_[b] = rotation_matrix<double>(q);
    const Vec3 c = c0_[b] + x.block<3, 1>(kD * b, 0);
    const Vec3 w = a.transpose() * angular_velocity(theta, x.block<3, 1>(kD * b + 3, 1));
    for (int j = 0; j < 3; ++j) {
      s[j] = c(j);
      s[7 + j] = x(kD * b + j, 1);
      s[10 + j] = w(j);
    }
    for (int j = 0; j < 4; ++j) s[3 + j] = q(j);
  }
  return within;
}

bool ModalCoordinates::accelerations(const ModeBlock& x, const double* ydot,
                                     Eigen::VectorXd& out) const {
  for (size_t b = 0; b < c0_.size(); ++b) {
    const double* d = ydot + kS * b;
    for (int j = 0; j < kS; ++j)
      if (!std::isfinite(d[j])) return false;
    const Mat3& a = orientation_[b];  // of the quaternion states() wrote
    out.segment<3>(kD * b) = Vec3(d[7], d[8], d[9]);
    out.segment<3>(kD * b + 3) = rotation_vector_acceleration(
        x.block<3, 1>(kD * b + 3, 0), x.block<3, 1>(kD * b + 3, 1), a * Vec3(d[10], d[11], d[12]));
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
