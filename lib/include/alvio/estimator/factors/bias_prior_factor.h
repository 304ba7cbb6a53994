#pragma once
// A Gaussian prior on the IMU biases of one keyframe, applied once at
// initialisation. Over a short window the accelerometer bias and a tilt of
// gravity are nearly indistinguishable; a weak prior (real IMUs have biases of
// ~0.1 m/s^2) resolves the ambiguity in favour of a plausible bias.
// Parameter block: speed-bias (9). Residual (6): [(ba - ba0)/sigma_a; (bg - bg0)/sigma_g].

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

namespace alvio {

class BiasPriorFactor : public ceres::SizedCostFunction<6, 9> {
 public:
  BiasPriorFactor(const Eigen::Vector3d& ba0, const Eigen::Vector3d& bg0, double sigma_a,
                  double sigma_g)
      : ba0_(ba0), bg0_(bg0), inv_sigma_a_(1.0 / sigma_a), inv_sigma_g_(1.0 / sigma_g) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Eigen::Matrix<double, 9, 1>> sb(parameters[0]);
    Eigen::Map<Eigen::Matrix<double, 6, 1>> r(residuals);
    r.head<3>() = inv_sigma_a_ * (sb.segment<3>(3) - ba0_);
    r.tail<3>() = inv_sigma_g_ * (sb.segment<3>(6) - bg0_);
    if (jacobians && jacobians[0]) {
      Eigen::Map<Eigen::Matrix<double, 6, 9, Eigen::RowMajor>> J(jacobians[0]);
      J.setZero();
      J.block<3, 3>(0, 3) = inv_sigma_a_ * Eigen::Matrix3d::Identity();
      J.block<3, 3>(3, 6) = inv_sigma_g_ * Eigen::Matrix3d::Identity();
    }
    return true;
  }

 private:
  Eigen::Vector3d ba0_, bg0_;
  double inv_sigma_a_, inv_sigma_g_;
};

}  // namespace alvio
