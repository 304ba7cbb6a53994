#include "alvio/geometry/orthonormal_line_manifold.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "alvio/geometry/so3_utils.h"

namespace alvio {

double wrapAngle(double a) {
  constexpr double kPi = 3.14159265358979323846;
  a = std::fmod(a + kPi, 2.0 * kPi);
  if (a <= 0.0) a += 2.0 * kPi;
  return a - kPi;
}

bool OrthonormalLineManifold::Plus(const double* x, const double* delta,
                                   double* x_plus_delta) const {
  const Eigen::Matrix3d U = expSO3(Eigen::Vector3d(x[0], x[1], x[2])) *
                            expSO3(Eigen::Vector3d(delta[0], delta[1], delta[2]));
  const Eigen::Vector3d theta = logSO3(U);
  std::copy(theta.data(), theta.data() + 3, x_plus_delta);
  x_plus_delta[3] = wrapAngle(x[3] + delta[3]);
  return true;
}

bool OrthonormalLineManifold::PlusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.topLeftCorner<3, 3>() = rightJacobianInverseSO3(Eigen::Vector3d(x[0], x[1], x[2]));
  J(3, 3) = 1.0;
  return true;
}

bool OrthonormalLineManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const Eigen::Matrix3d U_x = expSO3(Eigen::Vector3d(x[0], x[1], x[2]));
  const Eigen::Matrix3d U_y = expSO3(Eigen::Vector3d(y[0], y[1], y[2]));
  const Eigen::Vector3d dtheta = logSO3(U_x.transpose() * U_y);
  std::copy(dtheta.data(), dtheta.data() + 3, y_minus_x);
  y_minus_x[3] = wrapAngle(y[3] - x[3]);
  return true;
}

bool OrthonormalLineManifold::MinusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.topLeftCorner<3, 3>() = rightJacobianSO3(Eigen::Vector3d(x[0], x[1], x[2]));
  J(3, 3) = 1.0;
  return true;
}

}  // namespace alvio
