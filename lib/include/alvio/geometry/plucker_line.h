#pragma once
// A 3D line in Plucker coordinates L = (n, d): d is the direction and n = p x d the moment
// about the frame origin (p any point on the line), so n.d = 0. The pair is homogeneous:
// (s n, s d) for s != 0 is the same line. See docs/conventions-and-math.md.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace alvio {

struct PluckerLine {
  Eigen::Vector3d n = Eigen::Vector3d::UnitX();  ///< moment about the origin
  Eigen::Vector3d d = Eigen::Vector3d::UnitY();  ///< direction

  PluckerLine() = default;
  PluckerLine(const Eigen::Vector3d& moment, const Eigen::Vector3d& direction)
      : n(moment), d(direction) {}

  /// The line through p and q, directed from p to q.
  static PluckerLine fromPoints(const Eigen::Vector3d& p, const Eigen::Vector3d& q);

  /// The same line scaled so that |d| = 1 (then |n| is the distance to the origin).
  PluckerLine normalized() const;
  /// The point of the line closest to the origin.
  Eigen::Vector3d closestPointToOrigin() const { return d.cross(n) / d.squaredNorm(); }
  double distanceToOrigin() const { return n.norm() / d.norm(); }
  /// Distance of a point to the (infinite) line.
  double distanceTo(const Eigen::Vector3d& p) const;

  /// The line expressed in frame b, given in frame a and T_b_a (p_b = R_b_a p_a + t_b_a):
  /// n_b = R n_a + [t]x R d_a,  d_b = R d_a.
  PluckerLine transformed(const Eigen::Isometry3d& T_b_a) const;

  /// Image line of the line seen from a camera at this frame's origin, in normalised
  /// coordinates (K = I): a homogeneous 2D line l with l.[u, v, 1] = 0. It is n itself.
  const Eigen::Vector3d& normalisedImageLine() const { return n; }

  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// The image line in pixel coordinates of a camera-frame line: l_px = K_L n_c with
/// K_L = [[fy, 0, 0], [0, fx, 0], [-fy cx, -fx cy, fx fy]] (the cofactor matrix of K).
Eigen::Vector3d pixelImageLine(const Eigen::Vector3d& n_c, double fx, double fy, double cx,
                               double cy);

/// Signed distance of a 2D point (in the line's units) to a homogeneous 2D line.
inline double pointToImageLineDistance(const Eigen::Vector2d& p, const Eigen::Vector3d& l) {
  return (l.x() * p.x() + l.y() * p.y() + l.z()) / l.head<2>().norm();
}

/// Angle between two lines' directions in [0, pi/2] (orientation ignored).
double lineAngle(const PluckerLine& a, const PluckerLine& b);

}  // namespace alvio
