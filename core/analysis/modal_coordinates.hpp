// The modal integrator's physical coordinates of the free bodies
// (core/analysis/modal_integrator.hpp): per body the offsets x = (dc, theta) from a reference
// configuration (c0, A0), c = c0 + dc and A = exp([theta]x) A0 (global rotation vector), and their
// rates u = (v, dtheta/dt); and the way back to the model's 13 states per body (centre, quaternion,
// velocity, angular velocity in the body frame). The angular velocity is omega = J(theta) dtheta/dt
// (core/model/rotation.hpp), so dx/dt = u holds exactly.
//
// A part of the scene that floats (floating_parts: free bodies joined to each other by elements
// and to nothing fixed) and spins may be followed in a frame that turns with it
// (set_turning_frame): the part's reference turns rigidly at a constant angular velocity W about a
// centre moving at a constant velocity V, R(t) = exp([W](t - t0)), and its offsets are taken in
// that frame: c = s(t) + R (c0 + dc - s0) with s(t) = s0 + V (t - t0), A = R exp([theta]x) A0.
// The elastic forces turn with the bodies, so a rigid spin of the part is no offset at all; in
// fixed axes it is a second-order offset along the stiff modes that the exponential method treats
// as an explicit remainder of size K0 x offset (a free pair on a steel rod spinning at 8 rad/s:
// 6.6e3 N standing for 0.34 N of centripetal force), whose error its estimates miss (12 to 537
// rtol measured at rtol 1e-4 .. 1e-8, docs/transient_measurements.md "Floating scenes turn with
// their frame"). The frame adds the centrifugal and Coriolis accelerations, -W x (W x p) - 2 W x
// dp/dt, and omega_frame = omega - A^T W in body axes, all exact.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cmath>
#include <vector>

#include "core/analysis/exponential_step.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// The parts of the scene that float: each a set of free bodies (their indices in state order)
// joined to each other through elements and joints and to no fixed or driven body, so that they
// can turn and move together as one rigid body with every internal force turning with them (a
// spacecraft, a thrown or spinning assembly). Free bodies joined to a fixed body are in none.
std::vector<std::vector<int>> floating_parts(const Model& model);

// The motion of the free bodies `part` (indices in state order) of the 13 states y as one rigid
// body: the centre of mass, its velocity, and the angular velocity I^-1 L (L the angular momentum
// about the centre, I the inertia of the part about it; directions of I below 1e-12 of its
// largest are left out) [m, m/s, rad/s].
struct RigidMotion {
  Vec3 centre = Vec3::Zero(), velocity = Vec3::Zero(), angular_velocity = Vec3::Zero();
};
RigidMotion rigid_motion(const Model& model, const double* y, const std::vector<int>& part);

class ModalCoordinates {
 public:
  // The reference configuration: the centres (displacements from the bodies' initial positions)
  // and orientations of the 13 states of the model's free bodies.
  void set_reference(const Model& model, const double* states);
  int bodies() const { return static_cast<int>(c0_.size()); }

  // The reference of the bodies `part` (state order) turns with `motion` from t0 on (see above);
  // without a call it stays still. After set_reference.
  void set_turning_frame(double t0, const RigidMotion& motion, const std::vector<int>& part);
  bool turning() const { return !frames_.empty(); }
  // The fastest turning frame's angular velocity [rad/s]; 0 without one.
  double fastest_frame_rate() const;
  // That of the frame of body b (state order) [rad/s]; 0 in fixed axes.
  double frame_rate(int b) const {
    return frame_of_[b] >= 0 ? frames_[frame_of_[b]].omega.norm() : 0.0;
  }

  // The offsets and their rates (x: 6 per body, 2 columns) of the 13 states y at time t.
  void offsets(double t, const double* y, ModeBlock& x) const;

  // The 13 states of x at time t into y, all bodies written; false when `max_rotation` > 0 and a
  // body's rotation vector is longer (the first such body in *far_body). Keeps what
  // accelerations needs.
  bool states(double t, const ModeBlock& x, double* y, double max_rotation = 0.0,
              int* far_body = nullptr);

  // The accelerations (dv/dt, d^2 theta/dt^2) into `out` at x from the derivatives ydot of the
  // 13 states that states() last wrote for x; false when ydot is not finite.
  bool accelerations(const ModeBlock& x, const double* ydot, Eigen::VectorXd& out) const;

  // The map from increments of the offsets at x to increments of the generalized coordinates
  // (core/model/generalized.hpp: global dc and rotation increments) and its inverse, block
  // diagonal: per body R and R J(theta) (R the frame's rotation at the time of the last
  // states(), I in fixed axes; J the left Jacobian, dA = [J dtheta]x A). A tangent stiffness K
  // of the generalized coordinates is K T in the offsets'.
  void increment_maps(const ModeBlock& x, Eigen::SparseMatrix<double>* map,
                      Eigen::SparseMatrix<double>* inverse) const;

  // The largest rotation of a body from the reference at x [rad].
  double largest_rotation(const ModeBlock& x) const;

  // The error weight of offset j (0..5) of body b at x: rtol |u| + atol for the centre (u its
  // displacement from the initial position, as the other methods weight their states), rtol +
  // atol for the rotation vector.
  double offset_weight(int b, int j, const ModeBlock& x, double rtol, double atol) const {
    return j < 3 ? rtol * std::abs(c0_[b](j) + x(kDofsPerBody * b + j, 0)) + atol : rtol + atol;
  }

 private:
  // A turning frame: R(t) = exp([omega] (t - t0)) about s0 + velocity (t - t0).
  struct Frame {
    double t0 = 0.0;
    Vec3 s0 = Vec3::Zero(), velocity = Vec3::Zero(), omega = Vec3::Zero();
    Vec4 q = Vec4(1, 0, 0, 0);         // R at the time of the last states(), as a quaternion
    Mat3 rotation = Mat3::Identity();  // and as a matrix
    void at(double t);                 // sets q and rotation to R(t)
  };

  std::vector<Vec3> position_;  // the bodies' initial centres (Body::position)
  std::vector<Vec3> c0_;        // the reference centres' displacements from position_
  std::vector<Vec4> q0_;
  std::vector<Mat3> a0_;
  std::vector<Mat3> orientation_;  // the rotation matrices (in the frame) states() last wrote
  std::vector<Frame> frames_;
  std::vector<int> frame_of_;  // per body the index of its frame in frames_, -1: fixed axes
};

}  // namespace beamrail
