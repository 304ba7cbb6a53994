#pragma once
// Pairs camera frames with the IMU stream when they arrive separately (ROS
// callbacks): a frame is released once an IMU sample after it has arrived, so
// that the estimator can interpolate the IMU at the frame time, exactly as the
// offline runner does. Both queues are bounded; what does not fit, or comes too
// late, is dropped and counted so the caller can warn.
//
// Not thread-safe: the caller serialises access (the estimator nodelet holds a mutex).

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <utility>
#include <vector>

#include "alvio/common/types.h"

namespace alvio {

struct FrameImuSyncOptions {
  std::size_t max_frames = 20;  ///< frames waiting for IMU or for the estimator (1 s at 20 Hz)
  std::size_t max_imu = 4000;   ///< IMU samples waiting for a frame (20 s at 200 Hz)
};

struct FrameImuSyncCounts {
  std::size_t frames_overflow = 0;  ///< oldest waiting frame dropped for a newer one
  std::size_t frames_late = 0;      ///< frame not after the last released frame
  std::size_t imu_overflow = 0;     ///< oldest IMU sample dropped (no frame for too long)
  std::size_t imu_late = 0;         ///< IMU sample not after the newest one
  std::size_t droppedFrames() const { return frames_overflow + frames_late; }
  std::size_t droppedImu() const { return imu_overflow + imu_late; }
};

/// `Frame` is whatever the caller carries per image (a message pointer, a FeatureFrame).
template <typename Frame>
class FrameImuSynchronizer {
 public:
  struct Ready {
    int64_t t_ns = 0;
    Frame frame;
    /// IMU samples received since the previous release, time-ordered: feed them to the
    /// estimator before the frame. The last one is after the frame time.
    std::vector<ImuSample> imu;
  };

  explicit FrameImuSynchronizer(const FrameImuSyncOptions& options = FrameImuSyncOptions())
      : options_(options) {}

  /// Returns false when the sample is dropped (not after the newest sample).
  bool addImu(const ImuSample& sample) {
    if (have_imu_ && sample.t_ns <= newest_imu_ns_) {
      ++counts_.imu_late;
      return false;
    }
    have_imu_ = true;
    newest_imu_ns_ = sample.t_ns;
    imu_.push_back(sample);
    if (imu_.size() > options_.max_imu) {
      imu_.pop_front();
      ++counts_.imu_overflow;
    }
    return true;
  }

  /// Returns false when the frame is dropped as late. A full queue drops its oldest frame
  /// instead (the newest frames matter most to a robot).
  bool addFrame(int64_t t_ns, Frame frame) {
    if ((released_any_ && t_ns <= last_released_ns_) ||
        (!frames_.empty() && t_ns <= frames_.back().first)) {
      ++counts_.frames_late;
      return false;
    }
    frames_.emplace_back(t_ns, std::move(frame));
    if (frames_.size() > options_.max_frames) {
      frames_.pop_front();
      ++counts_.frames_overflow;
    }
    return true;
  }

  /// The oldest waiting frame once the IMU has passed its time, else nothing.
  std::optional<Ready> pop() {
    if (frames_.empty() || !have_imu_ || newest_imu_ns_ <= frames_.front().first)
      return std::nullopt;
    Ready ready;
    ready.t_ns = frames_.front().first;
    ready.frame = std::move(frames_.front().second);
    frames_.pop_front();
    ready.imu.assign(imu_.begin(), imu_.end());
    imu_.clear();
    released_any_ = true;
    last_released_ns_ = ready.t_ns;
    return ready;
  }

  std::size_t waitingFrames() const { return frames_.size(); }
  std::size_t waitingImu() const { return imu_.size(); }
  const FrameImuSyncCounts& counts() const { return counts_; }
  const FrameImuSyncOptions& options() const { return options_; }

 private:
  FrameImuSyncOptions options_;
  std::deque<std::pair<int64_t, Frame>> frames_;
  std::deque<ImuSample> imu_;
  bool have_imu_ = false, released_any_ = false;
  int64_t newest_imu_ns_ = 0, last_released_ns_ = 0;
  FrameImuSyncCounts counts_;
};

}  // namespace alvio
