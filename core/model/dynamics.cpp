#include "core/model/dynamics.hpp"

#include <cmath>

#include "core/model/forces.hpp"
#include "core/model/rotation.hpp"

namespace beamrail {

void state_derivative(const Model& model, Data& data, double t, const double* y, double* ydot) {
  set_state(model, data, y);
  set_driven_poses(model, data, t);
  compute_wrenches(model, data, t);
  for (int k = 0; k < model.n_free(); ++k) {
    const int i = model.free_bodies[k];
    const Body& b = model.bodies[i];
    const Pose<double>& p = data.pose[i];
    const Vec3& w = data.w[i];
    const Vec6& wr = data.wrench[i];
    Eigen::Map<Eigen::Matrix<double, kStatesPerBody, 1>> f(ydot + kStatesPerBody * k);
    f.segment<3>(0) = p.v;
    f.segment<4>(3) = 0.5 * quat_left_product_matrix(data.q[i]) * w;
    f.segment<3>(7) = wr.head<3>() / b.mass;
    f.segment<3>(10) =
        b.inertia_inverse * (p.A.transpose() * wr.tail<3>() - w.cross(b.inertia * w));
  }
}

void state_jacobian_blocks(const Model& model, Data& data, double t, const double* y,
                           std::vector<Mat13>& blocks) {
  set_state(model, data, y);
  set_driven_poses(model, data, t);
  compute_wrenches(model, data, t);
  const bool damped = has_damping(model);
  compute_tangent(model, data, t, damped);
  blocks.resize(model.pattern.blocks.size());

  for (size_t n = 0; n < model.pattern.blocks.size(); ++n) {
    const auto [row, col] = model.pattern.blocks[n];
    const int i = model.free_bodies[row], j = model.free_bodies[col];
    const Body& bi = model.bodies[i];
    const Pose<double>& pi = data.pose[i];
    const Pose<double>& pj = data.pose[j];
    const Mat6& k = data.stiffness[n];

    // d wrench_i / d state_j: chain rule through theta_j(q_j) and omega_j = A_j w_j.
    const Mat34 theta_q = rotation_increment_jacobian(data.q[j]);
    Eigen::Matrix<double, 6, kStatesPerBody> dw;
    dw.setZero();
    dw.block<6, 3>(0, 0) = k.leftCols<3>();
    dw.block<6, 4>(0, 3) = k.rightCols<3>() * theta_q;
    if (damped) {
      const Mat6& c = data.damping[n];
      dw.block<6, 4>(0, 3) -= c.rightCols<3>() * skew<double>(pj.omega) * theta_q;
      dw.block<6, 3>(0, 7) = c.leftCols<3>();
      dw.block<6, 3>(0, 10) = c.rightCols<3>() * pj.A;
    }

    Mat13& out = blocks[n];
    out.setZero();
    out.block<3, kStatesPerBody>(7, 0) = dw.topRows<3>() / bi.mass;
    const Mat3 jinv_at = bi.inertia_inverse * pi.A.transpose();
    out.block<3, kStatesPerBody>(10, 0) = jinv_at * dw.bottomRows<3>();

    if (row == col) {
      const Vec3& w = data.w[i];
      out.block<3, 3>(0, 7) = Mat3::Identity();
      out.block<4, 4>(3, 3) = 0.5 * quat_right_product_matrix(w);
      out.block<4, 3>(3, 10) = 0.5 * quat_left_product_matrix(data.q[i]);
      // A^T M with M fixed turns with the body: d(A^T M)/dtheta = A^T [M]x.
      out.block<3, 4>(10, 3) += jinv_at * skew<double>(data.wrench[i].tail<3>()) * theta_q;
      // Gyroscopic term: d(w x J w)/dw = [w]x J - [J w]x.
      out.block<3, 3>(10, 10) -=
          bi.inertia_inverse * (skew<double>(w) * bi.inertia - skew<double>(bi.inertia * w));
    }
  }
}

void scatter_dense(const Model& model, const std::vector<Mat13>& blocks, double* a, long ld) {
  const long n = model.n_states;
  for (long c = 0; c < n; ++c)
    for (long r = 0; r < n; ++r) a[c * ld + r] = 0.0;
  for (size_t b = 0; b < blocks.size(); ++b) {
    const long r0 = kStatesPerBody * model.pattern.blocks[b].row;
    const long c0 = kStatesPerBody * model.pattern.blocks[b].col;
    for (int c = 0; c < kStatesPerBody; ++c)
      for (int r = 0; r < kStatesPerBody; ++r) a[(c0 + c) * ld + r0 + r] += blocks[b](r, c);
  }
}

double normalize_quaternions(const Model& model, double* y) {
  double worst = 0.0;
  for (int k = 0; k < model.n_free(); ++k) {
    double* q = y + kStatesPerBody * k + 3;
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    worst = std::max(worst, std::abs(norm - 1.0));
    for (int j = 0; j < 4; ++j) q[j] /= norm;
  }
  return worst;
}

}  // namespace beamrail
