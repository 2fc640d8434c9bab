#include "core/analysis/sensitivity.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"
#include "core/model/jet3.hpp"
#include "core/model/model_numbers.hpp"
#include "core/model/rotation.hpp"
#include "core/model/wrench_assembly.hpp"

namespace beamrail {

namespace {

Vec4 conjugate(const Vec4& q) { return Vec4(q(0), -q(1), -q(2), -q(3)); }

Vec4 unit(const Vec4& q) { return q / q.norm(); }

using HVec = Eigen::Matrix<HyperDual, Eigen::Dynamic, 1>;

}  // namespace

namespace {

template <class J>
using JVec = Eigen::Matrix<J, Eigen::Dynamic, 1>;

// The poses of every body on the numbers J of `model` (a model of the scene of `base`): the state
// of `data` (each body's displacement, and its rotation from its initial orientation applied to
// `model`'s initial orientation), the free bodies then moved by each of `moves` in turn (J-valued,
// dim n_dofs, with no value part: X = (dc, theta) gives c + dc and (I + [theta]x) A, exact for
// nilpotent increments), at rest.
template <class J>
std::vector<Pose<J>> moved_poses(const Model& base, const Data& data, const ModelT<J>& model,
                                 const std::vector<JVec<J>>& moves) {
  std::vector<Pose<J>> out(base.bodies.size());
  for (size_t i = 0; i < base.bodies.size(); ++i) {
    const Mat3 relative =
        data.pose[i].A * rotation_matrix<double>(base.bodies[i].orientation).transpose();
    Pose<J>& p = out[i];
    p.A = relative.cast<J>() * rotation_matrix<J>(model.bodies[i].orientation);
    p.u = data.pose[i].u.cast<J>();
    p.v = Vec3T<J>::Zero();
    p.omega = Vec3T<J>::Zero();
    const int k = base.bodies[i].free_index;
    if (k < 0) continue;
    for (const JVec<J>& x : moves) {
      if (x.size() == 0) continue;
      p.u += x.template segment<3>(kDofsPerBody * k);
      const Vec3T<J> theta = x.template segment<3>(kDofsPerBody * k + 3);
      p.A = (Mat3T<J>::Identity() + skew<J>(theta)) * p.A;
    }
  }
  return out;
}

// x times the nilpotent unit `unit` (empty stays empty).
template <class J>
JVec<J> times(const Eigen::VectorXd& x, const J& unit) {
  JVec<J> out(x.size());
  for (Eigen::Index r = 0; r < x.size(); ++r) out(r) = x(r) * unit;
  return out;
}

// The generalized forces (dim n_dofs) of the elements (when `elements`) and the loads of `model`
// at the poses, at time t with the loads scaled by load_factor.
template <class J>
JVec<J> generalized_forces(const Model& base, const ModelT<J>& model,
                           const std::vector<Pose<J>>& poses, double t, double load_factor,
                           bool elements) {
  if (model.bodies.size() != base.bodies.size() || model.n_dofs != base.n_dofs)
    throw std::invalid_argument("the design direction's model has other bodies than the design's");
  std::vector<Vec6T<J>> wrench(base.bodies.size(), Vec6T<J>::Zero());
  add_load_wrenches(model, poses, t, load_factor, wrench);
  if (elements) add_element_wrenches(model, poses, wrench);
  JVec<J> out(base.n_dofs);
  for (int k = 0; k < base.n_free(); ++k)
    out.template segment<6>(kDofsPerBody * k) = wrench[base.free_bodies[k]];
  return out;
}

const HyperDual kE1(0.0, 1.0, 0.0, 0.0), kE2(0.0, 0.0, 1.0, 0.0);

}  // namespace

std::vector<Pose<HyperDual>> dual_poses(const Model& base, const Data& data,
                                        const DualModel& direction, const Eigen::VectorXd& v,
                                        const Eigen::VectorXd& phi) {
  return moved_poses<HyperDual>(base, data, direction, {times(v, kE2), times(phi, kE1)});
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
  return generalized_forces(base, direction, dual_poses(base, data, direction, v, phi), t,
                            load_factor, true);
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

namespace {

// The derivatives of the eigenvalues `values` (ascending) of a symmetric problem, cluster by
// cluster: pencil(first, last, mean) gives (A, B) over the cluster's modes, whose eigenvalues
// A x = d B x are the derivatives (B = I for M-normalized modes).
EigenvalueDerivatives cluster_derivatives(
    const std::vector<double>& values, bool complete,
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
    if (last == n - 1 && !complete) {
      // The values beyond the last may belong to this cluster: its derivatives are unknown.
      for (int i = first; i <= last; ++i)
        out.values[i] = std::numeric_limits<double>::quiet_NaN(), out.crossing[i] = 4;
      break;
    }
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

}  // namespace

EigenvalueDerivatives eigenvalue_derivatives(const Model& base_model, const Data& base,
                                             const DesignStep& step, const Eigen::VectorXd& v,
                                             double t, double load_factor,
                                             const std::vector<double>& lambdas,
                                             const Eigen::MatrixXd& shapes, bool complete) {
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
  return cluster_derivatives(lambdas, complete, [&](int first, int last, double mean) {
    const int size = last - first + 1;
    const auto phi = shapes.middleCols(first, size);
    const Eigen::MatrixXd a = phi.transpose() * dk_phi.middleCols(first, size) -
                              mean * (phi.transpose() * dm_phi.middleCols(first, size));
    return std::make_pair(a, Eigen::MatrixXd(Eigen::MatrixXd::Identity(size, size)));
  });
}

EigenvalueDerivatives buckling_factor_derivatives(const Model& reference, const Data& base,
                                                  const DualModel& reference_direction,
                                                  const DualModel& scaled_direction,
                                                  const Eigen::VectorXd& v, double t,
                                                  const std::vector<double>& factors,
                                                  const Eigen::MatrixXd& shapes, bool complete) {
  using H = HyperDual;
  const int n = reference.n_dofs;
  const Eigen::VectorXd none;
  // K0 at the reference state, with its constant loads' stiffness (as the analysis builds it).
  Data d = base;
  compute_wrenches(reference, d, t, 1.0);
  compute_tangent(reference, d, t, false, 1.0);
  const Eigen::SparseMatrix<double> k0 =
      symmetric_stiffness(reference, d, Eigen::VectorXd::Ones(n), nullptr);
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> factor(k0);
  if (factor.info() != Eigen::Success)
    throw std::runtime_error("the reference state's tangent stiffness could not be factored");
  // The scaled loads P1 at the reference state and dP1/dp (through du0/dp too); u1 = K0^-1 P1,
  // the motion per unit load factor, and du1/dp = K0^-1 (dP1/dp - dK0/dp u1) (K0 symmetric for
  // the conservative loads buckling admits, so dK0/dp u1 is the e1 e2 part along u1).
  const HVec p1 = generalized_forces(
      reference, scaled_direction,
      moved_poses<H>(reference, base, scaled_direction, {times(v, kE2)}), t, 1.0, false);
  Eigen::VectorXd p1_value(n), dp1(n);
  for (int r = 0; r < n; ++r) p1_value(r) = p1(r).v, dp1(r) = p1(r).b;
  const Eigen::VectorXd u1 = factor.solve(p1_value);
  const HVec along_u1 =
      dual_generalized_forces(reference, base, reference_direction, v, u1, t, 1.0);
  Eigen::VectorXd dk0_u1(n);
  for (int r = 0; r < n; ++r) dk0_u1(r) = -along_u1(r).ab;
  const Eigen::VectorXd w1 = factor.solve(Eigen::VectorXd(dp1 - dk0_u1));

  // Per mode: dK0/dp phi (e1 e2 of W0 along phi), and K1 phi, dK1/dp phi. K1 is the change of the
  // tangent along u1 plus the scaled loads' stiffness: -(d2 W0/du2 [phi, u1] + dW1/du phi); on
  // third-order jets with e1 the mode, e3 the motion u1 (+ e2 du1/dp) and e2 the design, the
  // e1 e3 part is the first term and the e1 e2 e3 part its derivative along the design.
  const ModelT<Jet3> jet_model = zip_numbers<Jet3>(
      [](const H& x) {
        Jet3 j(x.v);
        j.c[2] = x.b;
        return j;
      },
      reference_direction);
  Jet3 e1, e2, e3, e23;
  e1.c[1] = 1.0, e2.c[2] = 1.0, e3.c[4] = 1.0, e23.c[6] = 1.0;
  JVec<Jet3> motion = times(u1, e3);
  motion += times(w1, e23);
  const int m = static_cast<int>(shapes.cols());
  Eigen::MatrixXd dk0_phi(n, m), k1_phi(n, m), dk1_phi(n, m);
  for (int j = 0; j < m; ++j) {
    const Eigen::VectorXd phi = shapes.col(j);
    const HVec w0 = dual_generalized_forces(reference, base, reference_direction, v, phi, t, 1.0);
    const HVec ws = generalized_forces(
        reference, scaled_direction,
        moved_poses<H>(reference, base, scaled_direction, {times(v, kE2), times(phi, kE1)}), t, 1.0,
        false);
    const JVec<Jet3> wj = generalized_forces(
        reference, jet_model,
        moved_poses<Jet3>(reference, base, jet_model, {times(v, e2), motion, times(phi, e1)}), t,
        1.0, true);
    for (int r = 0; r < n; ++r) {
      dk0_phi(r, j) = -w0(r).ab;
      k1_phi(r, j) = -(wj(r).c[5] + ws(r).a);
      dk1_phi(r, j) = -(wj(r).c[7] + ws(r).ab);
    }
  }
  // (K0 + lambda K1) phi = 0: phi^T (dK0 + lambda dK1) phi + dlambda phi^T K1 phi = 0.
  return cluster_derivatives(factors, complete, [&](int first, int last, double mean) {
    const int size = last - first + 1;
    const auto phi = shapes.middleCols(first, size);
    const Eigen::MatrixXd a = -(phi.transpose() * dk0_phi.middleCols(first, size) +
                                mean * (phi.transpose() * dk1_phi.middleCols(first, size)));
    const Eigen::MatrixXd b = phi.transpose() * k1_phi.middleCols(first, size);
    return std::make_pair(a, b);
  });
}

}  // namespace beamrail
