#pragma once
// Small geometry helpers on 3D segments shared by the line map and its evaluation.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

namespace alvio {

/// A finite 3D segment between two endpoints.
struct Segment3 {
  Eigen::Vector3d p0 = Eigen::Vector3d::Zero();
  Eigen::Vector3d p1 = Eigen::Vector3d::Zero();
  double length() const { return (p1 - p0).norm(); }
  /// Unit direction p0 -> p1 (zero for a degenerate segment).
  Eigen::Vector3d direction() const {
    const double l = length();
    return l > 0 ? Eigen::Vector3d((p1 - p0) / l) : Eigen::Vector3d::Zero();
  }
};

/// Distance from `p` to the closest point of segment [a, b].
inline double pointSegmentDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                   const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double l2 = ab.squaredNorm();
  const double s = l2 > 0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (a + s * ab - p).norm();
}

/// Distance from `p` to the infinite line through `c` with unit direction `u`.
inline double pointLineDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& c,
                                const Eigen::Vector3d& u) {
  const Eigen::Vector3d d = p - c;
  return (d - d.dot(u) * u).norm();
}

/// Angle between two undirected lines given by unit directions, in [0, pi/2] (rad).
inline double lineAngle(const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  const double c = std::min(1.0, std::abs(u.dot(v)));
  // acos is ill-conditioned near 1: use atan2 of |u x v| and |u . v|.
  return std::atan2(u.cross(v).norm(), c);
}

/// Points along [p0, p1] with spacing at most `step` (both endpoints included).
inline std::vector<Eigen::Vector3d> sampleSegment(const Eigen::Vector3d& p0,
                                                  const Eigen::Vector3d& p1, double step) {
  const double l = (p1 - p0).norm();
  const int n = step > 0 ? std::max(1, static_cast<int>(std::ceil(l / step))) : 1;
  std::vector<Eigen::Vector3d> out;
  out.reserve(n + 1);
  for (int i = 0; i <= n; ++i) out.push_back(p0 + (p1 - p0) * (static_cast<double>(i) / n));
  return out;
}

}  // namespace alvio
