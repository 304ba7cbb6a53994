#include "alvio/geometry/so3_utils.h"

#include <cmath>

namespace alvio {
namespace {
// Below this angle the closed forms lose precision and the Taylor series take over.
constexpr double kSmallAngle = 1e-5;
}  // namespace

Eigen::Matrix3d expSO3(const Eigen::Vector3d& theta) {
  const double angle = theta.norm();
  if (angle < kSmallAngle) {
    // Second-order series; re-orthonormalised through a quaternion.
    const Eigen::Matrix3d K = skew(theta);
    Eigen::Quaterniond q(Eigen::Matrix3d(Eigen::Matrix3d::Identity() + K + 0.5 * K * K));
    return q.normalized().toRotationMatrix();
  }
  return Eigen::AngleAxisd(angle, theta / angle).toRotationMatrix();
}

Eigen::Vector3d logSO3(const Eigen::Matrix3d& R) {
  // Through a quaternion: Eigen's AngleAxis uses atan2, accurate at small and large angles,
  // and returns an angle in [0, pi].
  const Eigen::AngleAxisd aa(Eigen::Quaterniond(R).normalized());
  return aa.angle() * aa.axis();
}

Eigen::Matrix3d rightJacobianSO3(const Eigen::Vector3d& theta) {
  const double a = theta.norm();
  const Eigen::Matrix3d K = skew(theta);
  double c1, c2;  // Jr = I - c1 K + c2 K^2
  if (a < kSmallAngle) {
    c1 = 0.5 - a * a / 24.0;
    c2 = 1.0 / 6.0 - a * a / 120.0;
  } else {
    c1 = (1.0 - std::cos(a)) / (a * a);
    c2 = (a - std::sin(a)) / (a * a * a);
  }
  return Eigen::Matrix3d::Identity() - c1 * K + c2 * K * K;
}

Eigen::Matrix3d rightJacobianInverseSO3(const Eigen::Vector3d& theta) {
  const double a = theta.norm();
  const Eigen::Matrix3d K = skew(theta);
  // Jr^-1 = I + K/2 + c K^2 with c = (1 - (a/2) cot(a/2)) / a^2; this form stays finite at pi.
  double c;
  if (a < kSmallAngle) {
    c = 1.0 / 12.0 + a * a / 720.0;
  } else {
    const double half = 0.5 * a;
    c = (1.0 - half * std::cos(half) / std::sin(half)) / (a * a);
  }
  return Eigen::Matrix3d::Identity() + 0.5 * K + c * K * K;
}

Eigen::Matrix<double, 3, 4> rotationJacobianWrtQuaternion(const Eigen::Quaterniond& q,
                                                          const Eigen::Vector3d& v) {
  // R v = v + 2 w (a x v) + 2 a x (a x v), and a x (a x v) = a (a.v) - v (a.a).
  const Eigen::Vector3d a = q.vec();
  const double w = q.w();
  Eigen::Matrix<double, 3, 4> J;
  J.leftCols<3>() = -2.0 * w * skew(v) + 2.0 * (a.dot(v) * Eigen::Matrix3d::Identity() +
                                                a * v.transpose() - 2.0 * v * a.transpose());
  J.col(3) = 2.0 * a.cross(v);
  return J;
}

Eigen::Matrix<double, 3, 4> inverseRotationJacobianWrtQuaternion(const Eigen::Quaterniond& q,
                                                                 const Eigen::Vector3d& v) {
  // R(q)^T = R(conj(q)) with conj(q) = (-a, w): the chain rule flips the sign of the a-columns.
  Eigen::Matrix<double, 3, 4> J = rotationJacobianWrtQuaternion(q.conjugate(), v);
  J.leftCols<3>() *= -1.0;
  return J;
}

}  // namespace alvio
