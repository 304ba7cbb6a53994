#pragma once
// Second step of initialisation: align the up-to-scale visual trajectory with
// the IMU preintegrations to recover the gyroscope bias, the velocities, the
// gravity direction and the metric scale (VINS-Mono's linear alignment with
// gravity refinement on its 2-DoF tangent space).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "alvio/imu/imu_preintegration.h"

namespace alvio {

struct AlignmentFrame {
  Eigen::Matrix3d R_c0_b;            ///< body rotation in the visual reference frame
  Eigen::Vector3d p_c0_c;            ///< camera position in the reference frame (unscaled)
  ImuPreintegration* imu = nullptr;  ///< from the previous frame to this one (null for the first)
};

struct AlignmentResult {
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();
  Eigen::Vector3d gravity_c0 = Eigen::Vector3d::Zero();  ///< "up" vector (magnitude g) in c0
  double scale = 0;
  /// How far the window's motion departs from constant velocity, as the alignment sees it (m):
  /// the scale is read from that departure alone, so its relative error is about the rows'
  /// noise over this. A steady turn or cruise mid-flight leaves millimetres, and the least
  /// squares scale then shrinks towards zero with the noise in the visual positions.
  double scale_motion_m = 0;
  double residual_rms = 0;                       ///< of the alignment's rows (m, m/s)
  std::vector<Eigen::Vector3d> velocities_body;  ///< per frame, in its body frame
  std::string failure;                           ///< why it failed, when it did
};

/// Estimates the gyroscope bias and re-propagates every frame's preintegration with it,
/// then solves for velocities, gravity and scale. False (with `failure` set) when the
/// solution is implausible (gravity magnitude off by > 1 m/s^2, negative scale).
bool alignVisualInertial(std::vector<AlignmentFrame>& frames, const Eigen::Vector3d& t_b_c,
                         double gravity_magnitude, AlignmentResult* result);

}  // namespace alvio
