#include "alvio/estimator/factors/line_step_damping_factor.h"

#include <Eigen/Core>
#include <algorithm>
#include <stdexcept>
#include <string>

#include "alvio/geometry/orthonormal_line_manifold.h"
#include "alvio/geometry/so3_utils.h"

namespace alvio {

LineStepDampingFactor::LineStepDampingFactor(const double* start, double weight) : weight_(weight) {
  std::copy(start, start + 4, start_);
}

bool LineStepDampingFactor::Evaluate(double const* const* parameters, double* residuals,
                                     double** jacobians) const {
  const double* x = parameters[0];
  const Eigen::Vector3d theta(x[0], x[1], x[2]);
  // r_theta = log(U0^T U): with U = exp(theta), dr/dtheta = Jr^-1(r_theta) * Jr(theta).
  const Eigen::Vector3d r_theta =
      logSO3(expSO3(Eigen::Vector3d(start_[0], start_[1], start_[2])).transpose() * expSO3(theta));
  Eigen::Map<Eigen::Vector4d> r(residuals);
  r.head<3>() = weight_ * r_theta;
  r[3] = weight_ * wrapAngle(x[3] - start_[3]);
  if (jacobians && jacobians[0]) {
    Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> J(jacobians[0]);
    J.setZero();
    J.topLeftCorner<3, 3>() = weight_ * rightJacobianInverseSO3(r_theta) * rightJacobianSO3(theta);
    J(3, 3) = weight_;
  }
  return true;
}

LineStepDampingHalfFactor::LineStepDampingHalfFactor(const double* start, double weight, int half)
    : full_(start, weight), first_row_(2 * half) {
  if (half != 0 && half != 1)
    throw std::invalid_argument("LineStepDampingHalfFactor: half must be 0 or 1, not " +
                                std::to_string(half));
}

bool LineStepDampingHalfFactor::Evaluate(double const* const* parameters, double* residuals,
                                         double** jacobians) const {
  double r[4];
  double J[16];
  double* full_jacobians[1] = {J};
  if (!full_.Evaluate(parameters, r, jacobians && jacobians[0] ? full_jacobians : nullptr))
    return false;
  std::copy(r + first_row_, r + first_row_ + 2, residuals);
  if (jacobians && jacobians[0])
    std::copy(J + 4 * first_row_, J + 4 * (first_row_ + 2), jacobians[0]);
  return true;
}

}  // namespace alvio
