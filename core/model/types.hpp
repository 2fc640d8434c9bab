// Fixed-size Eigen types used throughout beamrail, templated on the scalar so that element kernels
// can run on doubles and on automatic-differentiation scalars alike.
#pragma once

#include <Eigen/Dense>

namespace beamrail {

template <class T>
using Vec3T = Eigen::Matrix<T, 3, 1>;
template <class T>
using Vec4T = Eigen::Matrix<T, 4, 1>;
template <class T>
using Vec6T = Eigen::Matrix<T, 6, 1>;
template <class T>
using Mat3T = Eigen::Matrix<T, 3, 3>;

using Vec3 = Vec3T<double>;
using Vec4 = Vec4T<double>;  // Euler parameters (q0 scalar, q1..q3 vector)
using Vec6 = Vec6T<double>;  // a wrench (force, moment) or a twist (velocity, angular velocity)
using Mat3 = Mat3T<double>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat34 = Eigen::Matrix<double, 3, 4>;
using Mat43 = Eigen::Matrix<double, 4, 3>;
using Mat4 = Eigen::Matrix<double, 4, 4>;

}  // namespace beamrail
