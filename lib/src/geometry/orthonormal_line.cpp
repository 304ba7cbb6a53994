#include "alvio/geometry/orthonormal_line.h"

#include <cmath>

#include "alvio/geometry/so3_utils.h"

namespace alvio {
namespace {
// Any unit vector perpendicular to the unit vector v.
Eigen::Vector3d anyPerpendicular(const Eigen::Vector3d& v) {
  const Eigen::Vector3d axis =
      std::abs(v.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  return v.cross(axis).normalized();
}
}  // namespace

OrthonormalLine OrthonormalLine::fromPlucker(const PluckerLine& line) {
  const Eigen::Vector3d u2 = line.d.normalized();
  // Remove any component of n along d left by rounding, so that U is exactly orthonormal.
  const Eigen::Vector3d n = line.n - line.n.dot(u2) * u2;
  const double n_norm = n.norm();
  const double d_norm = line.d.norm();
  OrthonormalLine o;
  const Eigen::Vector3d u1 =
      n_norm > 1e-12 * d_norm ? Eigen::Vector3d(n / n_norm) : anyPerpendicular(u2);
  o.U.col(0) = u1;
  o.U.col(1) = u2;
  o.U.col(2) = u1.cross(u2);
  o.phi = std::atan2(d_norm, n_norm);
  return o;
}

PluckerLine OrthonormalLine::toPlucker() const {
  return PluckerLine(std::cos(phi) * U.col(0), std::sin(phi) * U.col(1));
}

OrthonormalLine OrthonormalLine::fromParameters(const double* x) {
  OrthonormalLine o;
  o.U = expSO3(Eigen::Vector3d(x[0], x[1], x[2]));
  o.phi = x[3];
  return o;
}

void OrthonormalLine::toParameters(double* x) const {
  const Eigen::Vector3d theta = logSO3(U);
  x[0] = theta.x();
  x[1] = theta.y();
  x[2] = theta.z();
  x[3] = phi;
}

PluckerLine pluckerFromParameters(const double* x) {
  return OrthonormalLine::fromParameters(x).toPlucker();
}

Eigen::Matrix<double, 6, 4> pluckerJacobianWrtTangent(const double* x) {
  return pluckerJacobianWrtTangent(OrthonormalLine::fromParameters(x));
}

Eigen::Matrix<double, 6, 4> pluckerJacobianWrtTangent(const OrthonormalLine& line) {
  // U Exp(dtheta) ~= U (I + [dtheta]x): du1 = dtheta3 u2 - dtheta2 u3,
  // du2 = -dtheta3 u1 + dtheta1 u3; and (w1, w2) rotates: dw1 = -w2 dphi, dw2 = w1 dphi.
  const double w1 = std::cos(line.phi), w2 = std::sin(line.phi);
  const Eigen::Vector3d u1 = line.U.col(0), u2 = line.U.col(1), u3 = line.U.col(2);
  Eigen::Matrix<double, 6, 4> J;
  J.block<3, 1>(0, 0).setZero();
  J.block<3, 1>(0, 1) = -w1 * u3;
  J.block<3, 1>(0, 2) = w1 * u2;
  J.block<3, 1>(0, 3) = -w2 * u1;
  J.block<3, 1>(3, 0) = w2 * u3;
  J.block<3, 1>(3, 1).setZero();
  J.block<3, 1>(3, 2) = -w2 * u1;
  J.block<3, 1>(3, 3) = w1 * u2;
  return J;
}

}  // namespace alvio
