#pragma once
// The camera-to-IMU time shift from a recording alone (no calibration target): the camera's
// rotation between consecutive images, from its tracked points' bearings, compared with the
// gyroscope's over the same interval moved by each trial shift. Where they agree best is
// Kalibr's timeshift_cam_imu (t_imu = t_cam + shift). A constant gyroscope bias is taken out
// at every trial, so it does not pull the estimate.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "alvio/common/types.h"
#include "alvio/frontend/feature_frame.h"

namespace alvio {

/// The camera's rotation between two images, seen in their tracked points.
struct FrameRotation {
  int64_t t0_ns = 0, t1_ns = 0;  ///< the two images' stamps (camera clock)
  /// Rotation vector (rad) of the second camera's orientation in the first camera's frame.
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();
  int points = 0;  ///< points it was fitted on
};

/// The rotation between two frames from the points both track (their undistorted normalised
/// positions): the essential matrix's, fitted by RANSAC with `inlier_threshold` (normalised
/// units: about a pixel over the focal length), so that the translation's parallax does not pass
/// for rotation. Nothing when fewer than `min_points` are common to both or fit, or when the
/// fit is ambiguous.
std::optional<FrameRotation> rotationBetween(const FeatureFrame& first, const FeatureFrame& second,
                                             int min_points = 20, double inlier_threshold = 0.002);

struct TimeShiftOptions {
  double max_shift_s = 0.2;  ///< trial shifts from -max to +max
  double step_s = 0.001;     ///< between trial shifts; the minimum is refined between them
};

struct TimeShiftEstimate {
  double shift_s = 0;  ///< timeshift_cam_imu: t_imu = t_cam + shift
  std::vector<double> trial_shift_s;
  /// Per trial: the mean squared difference of the camera's and the gyroscope's angular
  /// velocity over the pairs, the constant bias removed ((rad/s)^2).
  std::vector<double> cost;
  std::size_t pairs = 0;    ///< image pairs inside the IMU's span at every trial
  double rms_rate_rps = 0;  ///< RMS of the camera's angular velocity over those pairs
  Eigen::Vector3d gyro_bias_rps = Eigen::Vector3d::Zero();  ///< at the estimate, camera frame
  bool at_search_edge = false;  ///< the minimum is the first or last trial: widen the search
};

/// Throws alvio::Error naming the problem when too few pairs lie inside the IMU's span or the
/// options are out of range. `R_b_c`: the camera's orientation in the body (IMU) frame.
TimeShiftEstimate estimateTimeShift(const std::vector<FrameRotation>& rotations,
                                    const std::vector<ImuSample>& imu, const Eigen::Matrix3d& R_b_c,
                                    const TimeShiftOptions& options = TimeShiftOptions());

}  // namespace alvio
