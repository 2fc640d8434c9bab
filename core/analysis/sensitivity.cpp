#include "core/analysis/sensitivity.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SparseLU>
#include <cmath>
#include <stdexcept>

#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"
#include "core/model/model_numbers.hpp"
#include "core/model/rotation.hpp"
#include "core/model/wrench_assembly.hpp"

namespace beamrail {

namespace {

Vec4 conjugate(const Vec4& q) { return Vec4(q(0), -q(1), -q(2), -q(3)); }

Vec4 unit(const Vec4& q) { return q / q.norm(); }

using HVec = Eigen::Matrix<HyperDual, Eigen::Dynamic, 1>;

}  // namespace

std::vector<Pose<HyperDual>> dual_poses(const Model& base, const Data& data,
                                        const DualModel& direction, const Eigen::VectorXd& v,
                                        const Eigen::VectorXd& phi) {
  using H = HyperDual;
  std::vector<Pose<H>> out(base.bodies.size());
  for (size_t i = 0; i < base.bodies.size(); ++i) {
    const Mat3 relative =
        data.pose[i].A * rotation_matrix<double>(base.bodies[i].orientation).transpose();
    Pose<H>& p = out[i];
    p.A = relative.cast<H>() * rotation_matrix<H>(direction.bodies[i].orientation);
    p.u = data.pose[i].u.cast<H>();
    p.v = Vec3T<H>::Zero();
    p.omega = Vec3T<H>::Zero();
    const int k = base.bodies[i].free_index;
    if (k < 0) continue;
    // Moved by e x = e (dc, theta): c + e dc and (I + e [theta]x) A, exact for e^2 = 0.
    const auto move = [&](const Eigen::VectorXd& x, bool e1) {
      if (x.size() == 0) return;
      Vec3T<H> dc, theta;
      for (int r = 0; r < 3; ++r) {
        const double c = x(kDofsPerBody * k + r), t = x(kDofsPerBody * k + 3 + r);
        dc(r) = e1 ? H(0.0, c, 0.0, 0.0) : H(0.0, 0.0, c, 0.0);
        theta(r) = e1 ? H(0.0, t, 0.0, 0.0) : H(0.0, 0.0, t, 0.0);
      }
      p.u += dc;
      p.A = (Mat3T<H>::Identity() + skew<H>(theta)) * p.A;
    };
    move(v, false);
    move(phi, true);
  }
  return out;
}

DualModel design_direction(const Model& base, const Model& plus, const Model& minus, double h) {
  return zip_numbers<HyperDual>(
      [h](double x, double p, double m) {
        return HyperDual(x, 0.0, p == m ? 0.0 : (p - m) / (2.0 * h), 0.0);
      },
      base, plus, minus);
}

HVec dual_generalized_forces(const Model& base, const Data& data, const DualModel& direction,
                             const Eigen::VectorXd& v, const Eigen::VectorXd& phi, double t,
                             double load_factor) {
  if (direction.bodies.size() != base.bodies.size() || direction.n_dofs != base.n_dofs)
    throw std::invalid_argument("dual_generalized_forces: the models have different bodies");
  const std::vector<Pose<HyperDual>> poses = dual_poses(base, data, direction, v, phi);
  std::vector<Vec6T<HyperDual>> wrench(base.bodies.size(), Vec6T<HyperDual>::Zero());
  add_load_wrenches(direction, poses, t, load_factor, wrench);
  add_element_wrenches(direction, poses, wrench);
  HVec out(base.n_dofs);
  for (int k = 0; k < base.n_free(); ++k)
    out.segment<6>(kDofsPerBody * k) = wrench[base.free_bodies[k]];
  return out;
}

void transplant_state(const Model& from_model, const Data& from, const Model& to_model, Data& to) {
  if (from_model.n_dofs != to_model.n_dofs || from_model.bodies.size() != to_model.bodies.size())
    throw std::invalid_argument("transplant_state: the models have different bodies");
  for (int i : to_model.free_bodies) {
    // The rotation from the initial orientation, applied to the other model's initial one.
    const Vec4 relative =
        quat_multiply(from.q[i], conjugate(unit(from_model.bodies[i].orientation)));
    to.q[i] = unit(quat_multiply(relative, unit(to_model.bodies[i].orientation)));
    to.pose[i].u = from.pose[i].u;
    to.pose[i].A = rotation_matrix<double>(to.q[i]);
    to.pose[i].v = from.pose[i].v;
    to.pose[i].omega = from.pose[i].omega;
    to.w[i] = from.w[i];
    to.rotation[i] = from.rotation[i];
  }
}

Data moved_state(const Model& base_model, const Data& base, const Model& model,
                 const Eigen::VectorXd& increment) {
  Data out(model);
  transplant_state(base_model, base, model, out);
  if (increment.size() > 0) apply_increment(model, out, increment);
  return out;
}

struct EquilibriumSensitivity::Factor {
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
};

EquilibriumSensitivity::EquilibriumSensitivity(const Model& model, const Data& data, double t,
                                               double load_factor)
    : model_(model), data_(data), t_(t), load_factor_(load_factor) {
  Data copy = data;
  compute_tangent(model, copy, t, false, load_factor);
  const Eigen::SparseMatrix<double> s = stiffness_matrix(model, copy);
  factor_ = std::make_unique<Factor>();
  factor_->lu.compute(s);
  if (factor_->lu.info() != Eigen::Success)
    failure_ =
        "the tangent stiffness at the equilibrium is singular (a body or mechanism free to "
        "move): the equilibrium does not depend smoothly on the design";
}

EquilibriumSensitivity::~EquilibriumSensitivity() = default;

Eigen::VectorXd EquilibriumSensitivity::state_derivative(const DesignStep& step) const {
  if (!failure_.empty()) return {};
  if (!step.direction) throw std::invalid_argument("state_derivative: no design direction");
  const HVec w = dual_generalized_forces(model_, data_, *step.direction, Eigen::VectorXd(),
                                         Eigen::VectorXd(), t_, load_factor_);
  Eigen::VectorXd dw(w.size());
  for (Eigen::Index r = 0; r < w.size(); ++r) dw(r) = w(r).b;
  // W(u(p), p) = 0: S du/dp + dW/dp = 0.
  Eigen::VectorXd v = factor_->lu.solve(-dw);
  return v;
}

double directional_derivative(const Model& base_model, const Data& base, const DesignStep& step,
                              const Eigen::VectorXd& v,
                              const std::function<double(const Model&, const Data&)>& q) {
  const Eigen::VectorXd forward = v.size() > 0 ? Eigen::VectorXd(step.h * v) : Eigen::VectorXd();
  const Eigen::VectorXd backward = v.size() > 0 ? Eigen::VectorXd(-step.h * v) : Eigen::VectorXd();
  const double up = q(*step.plus, moved_state(base_model, base, *step.plus, forward));
  const double down = q(*step.minus, moved_state(base_model, base, *step.minus, backward));
  return (up - down) / (2.0 * step.h);
}

namespace {

// The derivatives of the eigenvalues `values` (ascending) of a symmetric problem, cluster by
// cluster: pencil(first, last, mean) gives (A, B) over the cluster's modes, whose eigenvalues
// A x = d B x are the derivatives (B = I for M-normalized modes).
EigenvalueDerivatives cluster_derivatives(
    const std::vector<double>& values,
    const std::function<std::pair<Eigen::MatrixXd, Eigen::MatrixXd>(int, int, double)>& pencil) {
  const int n = static_cast<int>(values.size());
  EigenvalueDerivatives out;
  out.values.assign(n, 0.0);
  out.crossing.assign(n, 0);
  const auto close = [&](int a, int b, double gap) {
    const double scale = std::max(std::abs(values[a]), std::abs(values[b]));
    return std::abs(values[a] - values[b]) <= gap * scale;
  };
  for (int first = 0; first < n;) {
    int last = first;
    while (last + 1 < n && close(last, last + 1, kClusterGap)) ++last;
    const int size = last - first + 1;
    double mean = 0.0;
    for (int i = first; i <= last; ++i) mean += values[i] / size;
    const auto [a, b] = pencil(first, last, mean);
    if (size == 1) {
      out.values[first] = a(0, 0) / b(0, 0);
    } else {
      // B is definite (I, or phi^T K1 phi < 0 for loads that buckle): made positive.
      const double sign = b(0, 0) < 0.0 ? -1.0 : 1.0;
      const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(
          0.5 * sign * (a + a.transpose()), 0.5 * sign * (b + b.transpose()));
      // The cluster splits as p grows when its derivatives differ (a square section's bending
      // pair as its width grows); when they are equal (a round section's pair as its diameter
      // grows) it stays one repeated eigenvalue, whose derivative is that.
      const double spread = eig.eigenvalues().maxCoeff() - eig.eigenvalues().minCoeff();
      const double size_of = eig.eigenvalues().cwiseAbs().maxCoeff();
      for (int i = 0; i < size; ++i) {
        out.values[first + i] = eig.eigenvalues()(i);
        out.crossing[first + i] = spread > 1e-6 * size_of ? 2 : 3;
      }
    }
    first = last + 1;
  }
  // Near another eigenvalue that is not its cluster's.
  for (int i = 0; i < n; ++i)
    if (out.crossing[i] == 0 &&
        ((i > 0 && close(i - 1, i, kNearCrossing) && !close(i - 1, i, kClusterGap)) ||
         (i + 1 < n && close(i, i + 1, kNearCrossing) && !close(i, i + 1, kClusterGap))))
      out.crossing[i] = 1;
  return out;
}

Eigen::VectorXd scaled(const Eigen::VectorXd& v, double s) {
  return v.size() > 0 ? Eigen::VectorXd(s * v) : Eigen::VectorXd();
}

}  // namespace

EigenvalueDerivatives eigenvalue_derivatives(const Model& base_model, const Data& base,
                                             const DesignStep& step, const Eigen::VectorXd& v,
                                             double t, double load_factor,
                                             const std::vector<double>& lambdas,
                                             const Eigen::MatrixXd& shapes) {
  // d/dp (K phi) and d/dp (M phi) along the design direction (through du/dp too), exact: the
  // e1 e2 part of the generalized forces seeded with phi, and the e2 part of M phi.
  if (!step.direction) throw std::invalid_argument("eigenvalue_derivatives: no design direction");
  const DualModel& direction = *step.direction;
  const int n = static_cast<int>(shapes.cols());
  Eigen::MatrixXd dk_phi(base_model.n_dofs, n), dm_phi(base_model.n_dofs, n);
  const std::vector<Pose<HyperDual>> poses = dual_poses(base_model, base, direction, v, {});
  for (int j = 0; j < n; ++j) {
    const Eigen::VectorXd phi = shapes.col(j);
    const HVec w = dual_generalized_forces(base_model, base, direction, v, phi, t, load_factor);
    for (Eigen::Index r = 0; r < w.size(); ++r) dk_phi(r, j) = -w(r).ab;
    for (int k = 0; k < base_model.n_free(); ++k) {
      const int i = base_model.free_bodies[k];
      const BodyT<HyperDual>& b = direction.bodies[i];
      const Mat3T<HyperDual> j_global = poses[i].A * b.inertia * poses[i].A.transpose();
      const int o = kDofsPerBody * k;
      const Vec3T<HyperDual> translation = b.mass * phi.segment<3>(o).cast<HyperDual>();
      const Vec3T<HyperDual> rotation = j_global * phi.segment<3>(o + 3).cast<HyperDual>();
      for (int r = 0; r < 3; ++r) {
        dm_phi(o + r, j) = translation(r).b;
        dm_phi(o + 3 + r, j) = rotation(r).b;
      }
    }
  }
  return cluster_derivatives(lambdas, [&](int first, int last, double mean) {
    const int size = last - first + 1;
    const auto phi = shapes.middleCols(first, size);
    const Eigen::MatrixXd a = phi.transpose() * dk_phi.middleCols(first, size) -
                              mean * (phi.transpose() * dm_phi.middleCols(first, size));
    return std::make_pair(a, Eigen::MatrixXd(Eigen::MatrixXd::Identity(size, size)));
  });
}

EigenvalueDerivatives buckling_factor_derivatives(const Model& reference, const Data& base,
                                                  const DesignStep& reference_step,
                                                  const DesignStep& scaled_step,
                                                  const Eigen::VectorXd& v, double t,
                                                  const std::vector<double>& factors,
                                                  const Eigen::MatrixXd& shapes) {
  const auto at = [&](const Model& r, const Model& s, double sign) {
    Data d = moved_state(reference, base, r, scaled(v, sign * reference_step.h));
    compute_wrenches(r, d, t, 1.0);
    return buckling_matrices(r, s, t, d, false);
  };
  const BucklingMatrices plus = at(*reference_step.plus, *scaled_step.plus, 1.0);
  const BucklingMatrices minus = at(*reference_step.minus, *scaled_step.minus, -1.0);
  const double h2 = 2.0 * reference_step.h;
  const Eigen::MatrixXd dk0_phi = (plus.k0 * shapes - minus.k0 * shapes) / h2;
  const Eigen::MatrixXd dk1_phi = (plus.k1 * shapes - minus.k1 * shapes) / h2;
  const Eigen::MatrixXd k1_phi = 0.5 * (plus.k1 * shapes + minus.k1 * shapes);
  // (K0 + lambda K1) phi = 0: phi^T (dK0 + lambda dK1) phi + dlambda phi^T K1 phi = 0.
  return cluster_derivatives(factors, [&](int first, int last, double mean) {
    const int size = last - first + 1;
    const auto phi = shapes.middleCols(first, size);
    const Eigen::MatrixXd a = -(phi.transpose() * dk0_phi.middleCols(first, size) +
                                mean * (phi.transpose() * dk1_phi.middleCols(first, size)));
    const Eigen::MatrixXd b = phi.transpose() * k1_phi.middleCols(first, size);
    return std::make_pair(a, b);
  });
}

}  // namespace beamrail
