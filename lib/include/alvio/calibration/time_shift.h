#pragma once
// The camera-to-IMU time shift from a recording alone (no calibration target): the camera's
// rotation between consecutive images, from its tracked points (frame_rotation.h), against the
// gyroscope's over the same interval moved by each trial shift. Where they agree best is
// Kalibr's timeshift_cam_imu (t_imu = t_cam + shift). A constant gyroscope bias is taken out
// at every trial, so it does not pull the estimate.

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "alvio/calibration/frame_rotation.h"
#include "alvio/common/types.h"

namespace alvio {

struct TimeShiftOptions {
  double max_shift_s = 0.2;  ///< trial shifts from -max to +max
  double step_s = 0.001;     ///< between trial shifts; the minimum is refined between them
  /// Throws alvio::Error naming the option out of range.
  void validate() const;
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
