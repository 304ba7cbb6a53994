#pragma once
// Helpers for the line geometry tests: random states and central differences.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <functional>
#include <random>

#include "alvio/geometry/plucker_line.h"

namespace alvio::test {

inline Eigen::Vector3d randomVector(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return {u(rng), u(rng), u(rng)};
}

inline Eigen::Quaterniond randomRotation(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized();
}

inline Eigen::Isometry3d randomPose(std::mt19937& rng, double translation_scale) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = randomRotation(rng).toRotationMatrix();
  T.translation() = randomVector(rng, translation_scale);
  return T;
}

/// A camera at `position` looking at `target` (z forward, x right, y down-ish).
inline Eigen::Isometry3d lookAt(const Eigen::Vector3d& position, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - position).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitZ().cross(z).normalized();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << x, z.cross(x), z;
  T.translation() = position;
  return T;
}

inline Eigen::Vector2d projectNormalised(const Eigen::Isometry3d& T_w_c,
                                         const Eigen::Vector3d& p_w) {
  const Eigen::Vector3d p_c = T_w_c.inverse() * p_w;
  return p_c.head<2>() / p_c.z();
}

/// Jacobian of f: R^n -> R^m by central differences.
inline Eigen::MatrixXd numericJacobian(
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f, const Eigen::VectorXd& x,
    double h = 1e-6) {
  const Eigen::VectorXd f0 = f(x);
  Eigen::MatrixXd J(f0.size(), x.size());
  for (int i = 0; i < x.size(); ++i) {
    Eigen::VectorXd xp = x, xm = x;
    xp[i] += h;
    xm[i] -= h;
    J.col(i) = (f(xp) - f(xm)) / (2.0 * h);
  }
  return J;
}

/// Are two Plucker lines the same line (equal up to a non-zero scale)?
inline bool sameLine(const PluckerLine& a, const PluckerLine& b, double tol) {
  const PluckerLine an = a.normalized(), bn = b.normalized();
  // Flip b if its direction is opposite.
  const double sign = an.d.dot(bn.d) < 0 ? -1.0 : 1.0;
  return (an.d - sign * bn.d).norm() < tol && (an.n - sign * bn.n).norm() < tol;
}

}  // namespace alvio::test
