#include "core/analysis/sensitivity.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SparseLU>
#include <cmath>
#include <stdexcept>

#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"
#include "core/model/rotation.hpp"

namespace beamrail {

namespace {

Vec4 conjugate(const Vec4& q) { return Vec4(q(0), -q(1), -q(2), -q(3)); }

Vec4 unit(const Vec4& q) { return q / q.norm(); }

}  // namespace

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
  const auto wrench_at = [&](const Model& m) {
    Data d = moved_state(model_, data_, m, {});
    compute_wrenches(m, d, t_, load_factor_);
    return wrench_vector(m, d);
  };
  const Eigen::VectorXd dw = (wrench_at(*step.plus) - wrench_at(*step.minus)) / (2.0 * step.h);
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
  // K Phi and M Phi at the states moved along the design direction, from the tangent's blocks.
  const auto products_at = [&](const Model& m, double sign, Eigen::MatrixXd& k_phi,
                               Eigen::MatrixXd& m_phi) {
    Data d = moved_state(base_model, base, m, scaled(v, sign * step.h));
    compute_wrenches(m, d, t, load_factor);
    compute_tangent(m, d, t, false, load_factor);
    k_phi = symmetric_stiffness_product(m, d, shapes);
    m_phi = mass_product(m, d, shapes);
  };
  Eigen::MatrixXd kp, mp, km, mm;
  products_at(*step.plus, 1.0, kp, mp);
  products_at(*step.minus, -1.0, km, mm);
  const Eigen::MatrixXd dk_phi = (kp - km) / (2.0 * step.h);
  const Eigen::MatrixXd dm_phi = (mp - mm) / (2.0 * step.h);
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
