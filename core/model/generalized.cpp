#include "core/model/generalized.hpp"

#include <cmath>
#include <vector>

#include "core/model/rotation.hpp"

namespace beamrail {

Eigen::VectorXd wrench_vector(const Model& model, const Data& data) {
  Eigen::VectorXd w(model.n_dofs);
  for (int k = 0; k < model.n_free(); ++k)
    w.segment<kDofsPerBody>(kDofsPerBody * k) = data.wrench[model.free_bodies[k]];
  return w;
}

Eigen::SparseMatrix<double> stiffness_matrix(const Model& model, const Data& data) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(36 * model.pattern.blocks.size());
  for (size_t b = 0; b < model.pattern.blocks.size(); ++b) {
    const int r0 = kDofsPerBody * model.pattern.blocks[b].row;
    const int c0 = kDofsPerBody * model.pattern.blocks[b].col;
    for (int c = 0; c < 6; ++c)
      for (int r = 0; r < 6; ++r) entries.emplace_back(r0 + r, c0 + c, data.stiffness[b](r, c));
  }
  Eigen::SparseMatrix<double> k(model.n_dofs, model.n_dofs);
  k.setFromTriplets(entries.begin(), entries.end());
  return k;
}

Eigen::SparseMatrix<double> symmetric_stiffness(const Model& model, const Data& data,
                                                const Eigen::VectorXd& weight, double* asymmetry) {
  const BlockPattern& pattern = model.pattern;
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(36 * pattern.blocks.size());
  double norm = 0.0, skew = 0.0;
  for (size_t b = 0; b < pattern.blocks.size(); ++b) {
    const int r0 = kDofsPerBody * pattern.blocks[b].row;
    const int c0 = kDofsPerBody * pattern.blocks[b].col;
    const Mat6& s = data.stiffness[b];
    const Mat6& t = data.stiffness[pattern.transposed[b]];
    for (int c = 0; c < 6; ++c)
      for (int r = 0; r < 6; ++r) {
        const double w = weight(r0 + r) * weight(c0 + c);
        norm += w * w * s(r, c) * s(r, c);
        const double a = w * (s(r, c) - t(c, r));
        skew += a * a;
        entries.emplace_back(r0 + r, c0 + c, -0.5 * (s(r, c) + t(c, r)));
      }
  }
  if (asymmetry) *asymmetry = norm > 0.0 ? std::sqrt(skew / norm) : 0.0;
  Eigen::SparseMatrix<double> k(model.n_dofs, model.n_dofs);
  k.setFromTriplets(entries.begin(), entries.end());
  return k;
}

Eigen::VectorXd stiffness_weights(const Model& model, const Data& data) {
  Eigen::VectorXd w(model.n_dofs);
  for (int k = 0; k < model.n_free(); ++k)
    for (int i = 0; i < kDofsPerBody; ++i) {
      const double d = std::abs(data.stiffness[k](i, i));  // block k: free body k's diagonal
      w(kDofsPerBody * k + i) = d > 0.0 && std::isfinite(d) ? 1.0 / std::sqrt(d) : 1.0;
    }
  return w;
}

Eigen::MatrixXd symmetric_stiffness_product(const Model& model, const Data& data,
                                            const Eigen::MatrixXd& x) {
  Eigen::MatrixXd y = Eigen::MatrixXd::Zero(x.rows(), x.cols());
  for (size_t b = 0; b < model.pattern.blocks.size(); ++b) {
    const int r0 = kDofsPerBody * model.pattern.blocks[b].row;
    const int c0 = kDofsPerBody * model.pattern.blocks[b].col;
    const Mat6& s = data.stiffness[b];
    // K_rc = -(S_rc + S_cr^T) / 2: block b gives -S_b / 2 at (r, c) and -S_b^T / 2 at (c, r).
    y.middleRows<6>(r0).noalias() -= 0.5 * s * x.middleRows<6>(c0);
    y.middleRows<6>(c0).noalias() -= 0.5 * s.transpose() * x.middleRows<6>(r0);
  }
  return y;
}

Eigen::MatrixXd mass_product(const Model& model, const Data& data, const Eigen::MatrixXd& x) {
  Eigen::MatrixXd y(x.rows(), x.cols());
  for (int k = 0; k < model.n_free(); ++k) {
    const int i = model.free_bodies[k];
    const Body& b = model.bodies[i];
    const Mat3 j = data.pose[i].A * b.inertia * data.pose[i].A.transpose();
    const int o = kDofsPerBody * k;
    y.middleRows<3>(o) = b.mass * x.middleRows<3>(o);
    y.middleRows<3>(o + 3).noalias() = j * x.middleRows<3>(o + 3);
  }
  return y;
}

Eigen::SparseMatrix<double> mass_matrix(const Model& model, const Data& data) {
  std::vector<Eigen::Triplet<double>> entries;
  for (int k = 0; k < model.n_free(); ++k) {
    const int i = model.free_bodies[k];
    const Body& b = model.bodies[i];
    const Mat3 j = data.pose[i].A * b.inertia * data.pose[i].A.transpose();
    const int o = kDofsPerBody * k;
    for (int r = 0; r < 3; ++r) {
      entries.emplace_back(o + r, o + r, b.mass);
      for (int c = 0; c < 3; ++c) entries.emplace_back(o + 3 + r, o + 3 + c, j(r, c));
    }
  }
  Eigen::SparseMatrix<double> m(model.n_dofs, model.n_dofs);
  m.setFromTriplets(entries.begin(), entries.end());
  return m;
}

void apply_increment(const Model& model, Data& data, const Eigen::VectorXd& dx) {
  for (int k = 0; k < model.n_free(); ++k) {
    const int i = model.free_bodies[k];
    const Vec3 dc = dx.segment<3>(kDofsPerBody * k);
    const Vec3 dtheta = dx.segment<3>(kDofsPerBody * k + 3);
    data.pose[i].u += dc;
    data.q[i] = quat_multiply(quat_from_rotation_vector(dtheta), data.q[i]);
    data.q[i] /= data.q[i].norm();
    data.pose[i].A = rotation_matrix<double>(data.q[i]);
    const Mat3 a0 = rotation_matrix<double>(model.bodies[i].orientation);
    data.rotation[i] =
        rotation_vector_near(data.pose[i].A * a0.transpose(), data.rotation[i] + dtheta);
  }
}

void reset_to_initial(const Model& model, Data& data) {
  for (int i : model.free_bodies) {
    const Body& b = model.bodies[i];
    data.q[i] = b.orientation / b.orientation.norm();
    data.w[i].setZero();
    data.rotation[i].setZero();
    data.pose[i] = {Vec3::Zero(), rotation_matrix<double>(data.q[i]), Vec3::Zero(), Vec3::Zero()};
  }
}

}  // namespace beamrail
