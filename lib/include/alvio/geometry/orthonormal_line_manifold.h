#pragma once
// ceres::Manifold for a line in the orthonormal representation (see orthonormal_line.h).
//
// Ambient (4): [theta (rotation vector of U, |theta| <= pi), phi].
// Tangent (4): [dtheta, dphi], applied on the right: U <- U Exp(dtheta), W <- W R(dphi).
//   Plus(x, delta)  = [Log(Exp(theta) Exp(dtheta)), wrap(phi + dphi)]
//   Minus(y, x)     = [Log(Exp(theta_x)^T Exp(theta_y)), wrap(phi_y - phi_x)]
//   PlusJacobian    = blockdiag(Jr^-1(theta), 1),  MinusJacobian = blockdiag(Jr(theta), 1)
// phi is kept in (-pi, pi]. A rotation vector (not a quaternion) keeps the ambient size at 4,
// the size of the paper's state o = [psi, phi]; Jr^-1 stays finite because |theta| <= pi.

#include <ceres/manifold.h>

namespace alvio {

class OrthonormalLineManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 4; }
  int TangentSize() const override { return 4; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

/// Wrap an angle to (-pi, pi].
double wrapAngle(double a);

}  // namespace alvio
