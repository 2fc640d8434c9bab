#include "core/analysis/buckling_path.hpp"

#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"

namespace beamrail {

Eigen::MatrixXd path_stiffness_product(const Model& reference, const Model& scaled, double t,
                                       const Data& base, const Eigen::VectorXd& u1, double lambda,
                                       const Eigen::MatrixXd& x) {
  Data d = base;
  apply_increment(reference, d, lambda * u1);
  compute_tangent(reference, d, t, false, 1.0);  // the elements and the constant loads
  add_load_stiffness(scaled, d, t, lambda);      // the scaled loads' levers
  return symmetric_stiffness_product(reference, d, x);
}

}  // namespace beamrail
