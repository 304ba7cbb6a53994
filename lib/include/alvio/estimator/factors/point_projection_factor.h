#pragma once
// Reprojection of a point landmark, parameterised by its inverse depth in the
// keyframe i where it was first seen, into keyframe j.
// Parameter blocks: pose_i (7), pose_j (7), inverse_depth (1). Residual (2):
// normalised-plane error times `sqrt_info` (f / sigma_px gives pixels / sigma).

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace alvio {

class PointProjectionFactor : public ceres::SizedCostFunction<2, 7, 7, 1> {
 public:
  /// `obs_i`, `obs_j`: undistorted normalised observations (x, y). T_b_c: camera in body.
  PointProjectionFactor(const Eigen::Vector2d& obs_i, const Eigen::Vector2d& obs_j,
                        const Eigen::Isometry3d& T_b_c, double sqrt_info);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector3d pts_i_, pts_j_;
  Eigen::Matrix3d R_b_c_;
  Eigen::Vector3d t_b_c_;
  double sqrt_info_;
};

}  // namespace alvio
