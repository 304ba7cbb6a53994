#pragma once
// The 4-DoF orthonormal representation of a 3D line (Bartoli & Sturm), used as the
// optimisation variable of line landmarks:
//   U = [n/|n|, d/|d|, (n x d)/|n x d|] in SO(3),
//   W = [[w1, -w2], [w2, w1]] in SO(2), (w1, w2) = (|n|, |d|) / sqrt(|n|^2 + |d|^2).
// Back to Plucker: n = w1 u1, d = w2 u2 (scaled so that |n|^2 + |d|^2 = 1).
//
// Parameter block layout (4 doubles, see OrthonormalLineManifold):
//   [theta_x, theta_y, theta_z, phi], U = Exp(theta) with |theta| <= pi, W = R(phi),
//   i.e. w1 = cos(phi), w2 = sin(phi). The distance of the line to the origin is
//   w1 / w2 = cot(phi).

#include <Eigen/Core>

#include "alvio/geometry/plucker_line.h"

namespace alvio {

struct OrthonormalLine {
  static constexpr int kParameterSize = 4;

  Eigen::Matrix3d U = Eigen::Matrix3d::Identity();
  double phi = 0.25 * 3.14159265358979323846;  ///< W = R(phi)

  /// From Plucker coordinates (any scale). A line through the origin (n = 0) gets an
  /// arbitrary u1 perpendicular to d and phi = pi/2. n is made orthogonal to d first.
  static OrthonormalLine fromPlucker(const PluckerLine& line);
  /// Plucker coordinates with |n|^2 + |d|^2 = 1.
  PluckerLine toPlucker() const;

  /// Read/write the 4-double parameter block [theta (rotation vector of U), phi].
  static OrthonormalLine fromParameters(const double* x);
  void toParameters(double* x) const;

  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// Plucker coordinates straight from a parameter block (what the factor evaluates).
PluckerLine pluckerFromParameters(const double* x);

/// d(n, d) / d(tangent) at the parameter block, a 6x4 matrix (rows n then d), for the
/// tangent update U <- U Exp(dtheta), phi <- phi + dphi (OrthonormalLineManifold::Plus).
Eigen::Matrix<double, 6, 4> pluckerJacobianWrtTangent(const double* x);
/// Same, from U and phi already at hand.
Eigen::Matrix<double, 6, 4> pluckerJacobianWrtTangent(const OrthonormalLine& line);

}  // namespace alvio
