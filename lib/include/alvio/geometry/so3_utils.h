#pragma once
// Small SO(3) helpers shared by the line geometry and its Ceres factor: skew matrix,
// exponential/logarithm maps, the right Jacobian and its inverse, and the derivative
// of a quaternion rotation with respect to the quaternion's coefficients.
//
// Right Jacobian convention: Exp(theta + dtheta) ~= Exp(theta) * Exp(Jr(theta) * dtheta).

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace alvio {

/// [v]x, so that skew(a) * b = a x b.
inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

/// Rotation matrix of a rotation vector.
Eigen::Matrix3d expSO3(const Eigen::Vector3d& theta);
/// Rotation vector of a rotation matrix, with |theta| <= pi.
Eigen::Vector3d logSO3(const Eigen::Matrix3d& R);
/// Right Jacobian Jr(theta) of SO(3).
Eigen::Matrix3d rightJacobianSO3(const Eigen::Vector3d& theta);
/// Inverse of the right Jacobian; finite for |theta| <= pi (singular only at 2 pi).
Eigen::Matrix3d rightJacobianInverseSO3(const Eigen::Vector3d& theta);

/// d(R(q) v) / d[qx, qy, qz, qw] for R(q) as computed by Eigen's toRotationMatrix()
/// (R = I + 2 w [a]x + 2 [a]x^2, a = (qx, qy, qz)). The derivative is of that formula,
/// so it is also right off the unit sphere, as Ceres' ambient Jacobians need.
Eigen::Matrix<double, 3, 4> rotationJacobianWrtQuaternion(const Eigen::Quaterniond& q,
                                                          const Eigen::Vector3d& v);
/// d(R(q)^T v) / d[qx, qy, qz, qw], same formula.
Eigen::Matrix<double, 3, 4> inverseRotationJacobianWrtQuaternion(const Eigen::Quaterniond& q,
                                                                 const Eigen::Vector3d& v);

}  // namespace alvio
