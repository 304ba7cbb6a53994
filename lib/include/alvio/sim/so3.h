#pragma once
// Exp and Log of SO(3) on unit quaternions, written as templates so that the
// spline fit can differentiate them with Ceres' Jets.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace alvio::sim {

/// Rotation of angle |v| about v / |v|.
template <typename T>
Eigen::Quaternion<T> so3Exp(const Eigen::Matrix<T, 3, 1>& v) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T theta2 = v.squaredNorm();
  if (theta2 < T(1e-16)) {
    // Second-order Taylor expansion; exact enough and smooth for autodiff at 0.
    Eigen::Quaternion<T> q(T(1) - theta2 / T(8), v.x() / T(2), v.y() / T(2), v.z() / T(2));
    return q;
  }
  const T theta = sqrt(theta2);
  const T k = sin(theta / T(2)) / theta;
  return Eigen::Quaternion<T>(cos(theta / T(2)), k * v.x(), k * v.y(), k * v.z());
}

/// Rotation vector of q, with angle in [0, pi] (q and -q give the same result).
template <typename T>
Eigen::Matrix<T, 3, 1> so3Log(const Eigen::Quaternion<T>& q_in) {
  using std::atan2;
  using std::sqrt;
  Eigen::Quaternion<T> q = q_in;
  if (q.w() < T(0)) q.coeffs() = -q.coeffs();
  const T s2 = q.vec().squaredNorm();
  if (s2 < T(1e-16)) {
    // atan2(s, w)/s -> 1/w for small s.
    return q.vec() * (T(2) / q.w());
  }
  const T s = sqrt(s2);
  const T angle = T(2) * atan2(s, q.w());
  return q.vec() * (angle / s);
}

// Non-template overloads so that expressions (e.g. `w * d`) convert implicitly.
inline Eigen::Quaterniond so3Exp(const Eigen::Vector3d& v) {
  return so3Exp<double>(v);
}
inline Eigen::Vector3d so3Log(const Eigen::Quaterniond& q) {
  return so3Log<double>(q);
}

}  // namespace alvio::sim
