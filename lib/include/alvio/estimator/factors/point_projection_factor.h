#pragma once
// Reprojection of a point landmark, parameterised by its inverse depth in the
// keyframe i where it was first seen, into keyframe j.
// Parameter blocks: pose_i (7), pose_j (7), inverse_depth (1), and with
// estimateTimeShift() the camera's time shift td (1). Residual (2):
// normalised-plane error times `sqrt_info` (f / sigma_px gives pixels / sigma).
//
// The time shift (VINS-Mono's td, on top of camera.timeshift_cam_imu): an image stamped t
// was taken at t + td on the IMU's clock, so at the frame's time t each observation was
// where it is minus td times its image velocity.

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace alvio {

class PointProjectionFactor : public ceres::CostFunction {
 public:
  /// `obs_i`, `obs_j`: undistorted normalised observations (x, y). T_b_c: camera in body.
  PointProjectionFactor(const Eigen::Vector2d& obs_i, const Eigen::Vector2d& obs_j,
                        const Eigen::Isometry3d& T_b_c, double sqrt_info);
  /// Adds the time shift block: the observations' velocities, normalised units per second.
  void estimateTimeShift(const Eigen::Vector2d& velocity_i, const Eigen::Vector2d& velocity_j);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector3d pts_i_, pts_j_;
  Eigen::Vector3d velocity_i_ = Eigen::Vector3d::Zero(), velocity_j_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_b_c_;
  Eigen::Vector3d t_b_c_;
  double sqrt_info_;
};

}  // namespace alvio
