#pragma once
// The camera's rotation between two frames from the gyroscope alone (no bias: the tracker
// nodelet has no estimate of it, and 0.08 rad/s moves a point under 2 px in one 20 Hz frame).
// KLT started where this rotation moves each point has only the translation's few pixels
// left to find, so it needs fewer pyramid levels.

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <optional>

#include "alvio/common/types.h"

namespace alvio {

class GyroRotation {
 public:
  /// `R_b_c`: the camera's orientation in the body (IMU) frame.
  explicit GyroRotation(const Eigen::Matrix3d& R_b_c) : R_b_c_(R_b_c) {}

  /// Samples must come in time order; one not after the newest, or with a NaN or infinite
  /// rate, is ignored.
  void add(const ImuSample& sample);
  void clear() { samples_.clear(); }

  /// R_c1_c0, which maps a direction seen by the camera at t0 into the camera at t1 (the
  /// gyroscope's rate taken as linear between samples). Nothing when the samples do not
  /// reach from t0 to t1.
  std::optional<Eigen::Matrix3d> cameraRotation(int64_t t0_ns, int64_t t1_ns) const;

  /// Forget the samples no longer needed for intervals starting at or after t_ns.
  void dropBefore(int64_t t_ns);

  std::size_t size() const { return samples_.size(); }

 private:
  struct Rate {
    int64_t t_ns;
    Eigen::Vector3d w;
  };
  Eigen::Matrix3d R_b_c_;
  std::deque<Rate> samples_;
};

}  // namespace alvio
