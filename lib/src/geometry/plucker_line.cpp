#include "alvio/geometry/plucker_line.h"

#include <algorithm>
#include <cmath>

#include "alvio/geometry/so3_utils.h"

namespace alvio {

PluckerLine PluckerLine::fromPoints(const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  const Eigen::Vector3d d = q - p;
  return PluckerLine(p.cross(d), d);
}

PluckerLine PluckerLine::normalized() const {
  const double s = 1.0 / d.norm();
  return PluckerLine(s * n, s * d);
}

double PluckerLine::distanceTo(const Eigen::Vector3d& p) const {
  // The moment about p is n - p x d; its norm over |d| is the distance.
  return (n - p.cross(d)).norm() / d.norm();
}

PluckerLine PluckerLine::transformed(const Eigen::Isometry3d& T_b_a) const {
  const Eigen::Matrix3d R = T_b_a.linear();
  const Eigen::Vector3d d_b = R * d;
  return PluckerLine(R * n + skew(T_b_a.translation()) * d_b, d_b);
}

Eigen::Vector3d pixelImageLine(const Eigen::Vector3d& n_c, double fx, double fy, double cx,
                               double cy) {
  Eigen::Matrix3d K_L;
  K_L << fy, 0.0, 0.0, 0.0, fx, 0.0, -fy * cx, -fx * cy, fx * fy;
  return K_L * n_c;
}

double lineAngle(const PluckerLine& a, const PluckerLine& b) {
  const double c = std::abs(a.d.normalized().dot(b.d.normalized()));
  return std::acos(std::min(1.0, c));
}

}  // namespace alvio
