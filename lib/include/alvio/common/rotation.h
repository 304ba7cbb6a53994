#pragma once
// Small rotation helpers used across the estimator. Quaternions are Eigen's
// (Hamilton, w-last storage); "right perturbation" means R <- R Exp(theta).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace alvio {

template <typename Derived>
Eigen::Matrix<typename Derived::Scalar, 3, 3> skew(const Eigen::MatrixBase<Derived>& v) {
  Eigen::Matrix<typename Derived::Scalar, 3, 3> m;
  m << typename Derived::Scalar(0), -v(2), v(1), v(2), typename Derived::Scalar(0), -v(0), -v(1),
      v(0), typename Derived::Scalar(0);
  return m;
}

/// First-order quaternion of a small rotation vector (not normalised, as in preintegration).
template <typename Derived>
Eigen::Quaternion<typename Derived::Scalar> smallAngleQuaternion(
    const Eigen::MatrixBase<Derived>& theta) {
  using T = typename Derived::Scalar;
  const Eigen::Matrix<T, 3, 1> half = theta / T(2);
  return Eigen::Quaternion<T>(T(1), half.x(), half.y(), half.z());
}

/// Exact exponential map of a rotation vector.
inline Eigen::Quaterniond expQuaternion(const Eigen::Vector3d& theta) {
  const double angle = theta.norm();
  if (angle < 1e-12)
    return Eigen::Quaterniond(1, theta.x() / 2, theta.y() / 2, theta.z() / 2).normalized();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, theta / angle));
}

/// Rotation vector of a quaternion (angle in [0, pi]).
inline Eigen::Vector3d logQuaternion(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const double sin_half = q.vec().norm();
  if (sin_half < 1e-12) return 2.0 * q.vec();
  const double angle = 2.0 * std::atan2(sin_half, q.w());
  return q.vec() * (angle / sin_half);
}

/// Left and right quaternion-product matrices: (p*q).coeffs4 = left(p) * q = right(q) * p,
/// in [w, x, y, z] order.
inline Eigen::Matrix4d quaternionLeft(const Eigen::Quaterniond& p) {
  Eigen::Matrix4d m;
  m(0, 0) = p.w();
  m.block<1, 3>(0, 1) = -p.vec().transpose();
  m.block<3, 1>(1, 0) = p.vec();
  m.block<3, 3>(1, 1) = p.w() * Eigen::Matrix3d::Identity() + skew(p.vec());
  return m;
}
inline Eigen::Matrix4d quaternionRight(const Eigen::Quaterniond& q) {
  Eigen::Matrix4d m;
  m(0, 0) = q.w();
  m.block<1, 3>(0, 1) = -q.vec().transpose();
  m.block<3, 1>(1, 0) = q.vec();
  m.block<3, 3>(1, 1) = q.w() * Eigen::Matrix3d::Identity() - skew(q.vec());
  return m;
}

/// Yaw (about z) of a rotation, in radians, for z-y-x Euler angles. Ill-defined when the
/// body x axis is near vertical (as on the EuRoC MAV): prefer yawAlignment() for differences.
inline double yawOf(const Eigen::Matrix3d& R) {
  return std::atan2(R(1, 0), R(0, 0));
}

/// The rotation angle psi about z that best maps `R_source` onto `R_target`
/// (minimises |Rz(psi) R_source - R_target|_F). Well defined for any body orientation,
/// unlike a difference of Euler yaws.
inline double yawAlignment(const Eigen::Matrix3d& R_target, const Eigen::Matrix3d& R_source) {
  const Eigen::Matrix3d M = R_target * R_source.transpose();
  return std::atan2(M(1, 0) - M(0, 1), M(0, 0) + M(1, 1));
}

/// Rotation R_w_x that maps the measured gravity direction `g_x` (pointing up, as an
/// accelerometer at rest reads it) onto +z, with zero yaw.
inline Eigen::Matrix3d gravityAlignedRotation(const Eigen::Vector3d& g_x) {
  const Eigen::Matrix3d R0 =
      Eigen::Quaterniond::FromTwoVectors(g_x.normalized(), Eigen::Vector3d::UnitZ())
          .toRotationMatrix();
  return Eigen::AngleAxisd(-yawOf(R0), Eigen::Vector3d::UnitZ()).toRotationMatrix() * R0;
}

}  // namespace alvio
