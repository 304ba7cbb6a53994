#pragma once
// IMU preintegration factor between consecutive keyframes i and j.
// Parameter blocks: pose_i (7), speed_bias_i (9), pose_j (7), speed_bias_j (9).
// Residual (15): [p, q, v, ba, bg], whitened by the preintegration covariance.

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "alvio/imu/imu_preintegration.h"

namespace alvio {

class ImuFactor : public ceres::SizedCostFunction<15, 7, 9, 7, 9> {
 public:
  /// `preintegration` must outlive the factor. `gravity` is g in the world frame (0, 0, -9.81).
  ImuFactor(const ImuPreintegration* preintegration, const Eigen::Vector3d& gravity);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  const ImuPreintegration* pre_;
  Eigen::Vector3d gravity_;
  Eigen::Matrix<double, 15, 15> sqrt_information_;
};

}  // namespace alvio
