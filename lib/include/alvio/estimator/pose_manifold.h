#pragma once
// Parameter-block layout shared by every factor of the sliding window.
//
//   pose block        [tx, ty, tz, qx, qy, qz, qw]  (T_w_b; Eigen quaternion storage order)
//   speed-bias block  [vx, vy, vz, bax, bay, baz, bgx, bgy, bgz]
//
// The pose manifold is Ceres' ProductManifold<EuclideanManifold<3>,
// EigenQuaternionManifold>; factors return true *ambient* Jacobians (2x7,
// 15x7, ...). They are derived for a right perturbation R <- R Exp(theta) and
// converted by rightRotationJacobianToQuaternion().

#include <ceres/manifold.h>
#include <ceres/product_manifold.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "alvio/common/rotation.h"

namespace alvio {

constexpr int kPoseSize = 7;
constexpr int kPoseTangentSize = 6;
constexpr int kSpeedBiasSize = 9;

using PoseManifold =
    ceres::ProductManifold<ceres::EuclideanManifold<3>, ceres::EigenQuaternionManifold>;

/// d(Plus(q, delta))/d(delta) at delta = 0 for EigenQuaternionManifold, rows x,y,z,w.
/// Its columns are orthonormal (P^T P = I).
inline Eigen::Matrix<double, 4, 3> quaternionPlusJacobian(const Eigen::Quaterniond& q) {
  Eigen::Matrix<double, 4, 3> P;
  P.topRows<3>() = q.w() * Eigen::Matrix3d::Identity() - skew(q.vec());
  P.bottomRows<1>() = -q.vec().transpose();
  return P;
}

/// Ambient Jacobian (N x 4, w.r.t. qx qy qz qw) from a Jacobian w.r.t. a right-perturbation
/// rotation vector (N x 3). EigenQuaternionManifold's delta is a left half-angle vector:
/// R Exp(theta) = Exp(2 delta) R, so theta = 2 R^T delta.
/// `R` is q's rotation matrix, for callers that have it already.
template <int N>
Eigen::Matrix<double, N, 4> rightRotationJacobianToQuaternion(
    const Eigen::Matrix<double, N, 3>& J_theta, const Eigen::Quaterniond& q,
    const Eigen::Matrix3d& R) {
  return 2.0 * J_theta * R.transpose() * quaternionPlusJacobian(q).transpose();
}
template <int N>
Eigen::Matrix<double, N, 4> rightRotationJacobianToQuaternion(
    const Eigen::Matrix<double, N, 3>& J_theta, const Eigen::Quaterniond& q) {
  return rightRotationJacobianToQuaternion<N>(J_theta, q, q.toRotationMatrix());
}

/// d(Plus(x, delta))/d(delta) at delta = 0 of the whole pose manifold (7 x 6).
inline Eigen::Matrix<double, 7, 6> posePlusJacobian(const double* pose) {
  Eigen::Matrix<double, 7, 6> J = Eigen::Matrix<double, 7, 6>::Zero();
  J.topLeftCorner<3, 3>().setIdentity();
  J.bottomRightCorner<4, 3>() =
      quaternionPlusJacobian(Eigen::Map<const Eigen::Quaterniond>(pose + 3));
  return J;
}

inline Eigen::Map<const Eigen::Vector3d> posePosition(const double* pose) {
  return Eigen::Map<const Eigen::Vector3d>(pose);
}
inline Eigen::Map<const Eigen::Quaterniond> poseRotation(const double* pose) {
  return Eigen::Map<const Eigen::Quaterniond>(pose + 3);
}

}  // namespace alvio
