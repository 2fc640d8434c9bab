// The modal integrator's physical coordinates of the free bodies
// (core/analysis/modal_integrator.hpp): per body the offsets x = (dc, theta) from a reference
// configuration (c0, A0), c = c0 + dc and A = exp([theta]x) A0 (global rotation vector), and their
// rates u = (v, dtheta/dt); and the way back to the model's 13 states per body (centre, quaternion,
// velocity, angular velocity in the body frame). The angular velocity is omega = J(theta) dtheta/dt
// (core/model/rotation.hpp), so dx/dt = u holds exactly.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "core/analysis/exponential_step.hpp"
#include "core/model/model.hpp"

namespace beamrail {

class ModalCoordinates {
 public:
  // The reference configuration: the centres and orientations of the 13 states of `bodies`
  // free bodies.
  void set_reference(const double* states, int bodies);
  int bodies() const { return static_cast<int>(c0_.size()); }

  // The offsets and their rates (x: 6 per body, 2 columns) of the 13 states y.
  void offsets(const double* y, ModeBlock& x) const;

  // The 13 states of x into y, all bodies written; false when `max_rotation` > 0 and a body's
  // rotation vector is longer (the first such body in *far_body). Keeps the orientations for
  // accelerations.
  bool states(const ModeBlock& x, double* y, double max_rotation = 0.0, int* far_body = nullptr);

  // The accelerations (dv/dt, d^2 theta/dt^2) into `out` at x from the derivatives ydot of the
  // 13 states that states() last wrote for x; false when ydot is not finite.
  bool accelerations(const ModeBlock& x, const double* ydot, Eigen::VectorXd& out) const;

  // The largest rotation of a body from the reference at x [rad].
  double largest_rotation(const ModeBlock& x) const;

  // The error weight of offset j (0..5) of body b at x: rtol |c| + atol for the centre, rtol +
  // atol for the rotation vector.
  double offset_weight(int b, int j, const ModeBlock& x, double rtol, double atol) const {
    return j < 3 ? rtol * std::abs(c0_[b](j) + x(kDofsPerBody * b + j, 0)) + atol : rtol + atol;
  }

 private:
  std::vector<Vec3> c0_;
  std::vector<Vec4> q0_;
  std::vector<Mat3> a0_;
  std::vector<Mat3> orientation_;  // the rotation matrices of the 13 states states() last wrote
};

}  // namespace beamrail
