#pragma once
// Pairs camera frames with the IMU stream when they arrive separately (ROS
// callbacks): a frame is released once an IMU sample after it has arrived, so
// that the estimator can interpolate the IMU at the frame time, exactly as the
// offline runner does. Both queues are bounded; what does not fit, or comes too
// late, is dropped and counted so the caller can warn.
//
// The IMU's clock jumping back (a bag played again, a restarted simulation) starts a new run:
// what waits from the old clock is dropped, and so are the old clock's frames still on their
// way. The IMU decides, as it comes straight from the sensor and frames lag behind it. A frame
// whose clock jumped back before the IMU's is held for the new run.
//
// Not thread-safe: the caller serialises access (the estimator nodelet holds a mutex).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <utility>
#include <vector>

#include "alvio/common/clock_jump.h"
#include "alvio/common/types.h"

namespace alvio {

struct FrameImuSyncOptions {
  std::size_t max_frames = 20;  ///< frames waiting for IMU or for the estimator (1 s at 20 Hz)
  std::size_t max_imu = 4000;   ///< IMU samples waiting for a frame (20 s at 200 Hz)
};

/// Counted since the IMU's last clock jump: a new run counts afresh.
struct FrameImuSyncCounts {
  std::size_t frames_overflow = 0;  ///< oldest waiting frame dropped for a newer one
  std::size_t frames_late = 0;      ///< frame not after the last released frame
  std::size_t imu_overflow = 0;     ///< oldest IMU sample dropped (no frame for too long)
  std::size_t imu_late = 0;         ///< IMU sample not after the newest one
  /// Frames stamped on the clock before the IMU's jump: the old run's, so not in droppedFrames().
  std::size_t frames_old_clock = 0;
  std::size_t droppedFrames() const { return frames_overflow + frames_late; }
  std::size_t droppedImu() const { return imu_overflow + imu_late; }
};

enum class ImuAdded {
  kQueued,
  kLate,    ///< not after the newest sample: dropped
  kNewRun,  ///< its clock jumped back: the old clock's frames and IMU were dropped, it was kept
};

enum class FrameAdded {
  kQueued,
  kHeld,      ///< its clock jumped back before the IMU's: waits for the IMU's jump
  kLate,      ///< not after the previous frame: dropped
  kOldClock,  ///< stamped on the clock before the IMU's jump: dropped
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

  ImuAdded addImu(const ImuSample& sample) {
    const int64_t newest_before = imu_clock_.newest();
    last_jump_ns_ = imu_clock_.follow(sample.t_ns);
    if (last_jump_ns_) {
      startNewRun();
    } else if (staleStamp(sample.t_ns, newest_before)) {
      ++counts_.imu_late;
      return ImuAdded::kLate;
    }
    imu_.push_back(sample);
    if (imu_.size() > options_.max_imu) {
      imu_.pop_front();
      ++counts_.imu_overflow;
    }
    return last_jump_ns_ ? ImuAdded::kNewRun : ImuAdded::kQueued;
  }

  /// A full queue drops its oldest frame instead (the newest frames matter most to a robot).
  FrameAdded addFrame(int64_t t_ns, Frame frame) {
    // Left waiting for the new clock's IMU, the old clock's last frame would hold back every
    // frame after it until the new clock caught up with it.
    if (imu_clock_.laggingOnOldClock(t_ns)) {
      ++counts_.frames_old_clock;
      return FrameAdded::kOldClock;
    }
    const bool camera_jumped = clockJumpedBack(t_ns, newest_frame_ns_);
    // The IMU still on the camera's old clock, more than a jump ahead of this frame.
    const bool imu_on_old_clock = clockJumpedBack(t_ns, imu_clock_.newest()) &&
                                  !clockJumpedBack(imu_clock_.newest(), newest_frame_ns_);
    newest_frame_ns_ = camera_jumped ? t_ns : std::max(newest_frame_ns_, t_ns);
    if (camera_jumped && imu_on_old_clock) {
      held_.clear();
      pushBounded(&held_, t_ns, std::move(frame));
      return FrameAdded::kHeld;
    }
    if (!held_.empty()) {
      if (t_ns <= held_.back().first) {
        ++counts_.frames_late;
        return FrameAdded::kLate;
      }
      if (!clockJumpedBack(held_.back().first, t_ns)) {
        pushBounded(&held_, t_ns, std::move(frame));
        return FrameAdded::kHeld;
      }
      // Back more than a jump ahead, on the IMU's clock: the held frames were stragglers
      // reordered by over kClockJumpBackNs, not a new clock.
      counts_.frames_late += held_.size();
      held_.clear();
    }
    if ((released_any_ && t_ns <= last_released_ns_) ||
        (!frames_.empty() && t_ns <= frames_.back().first)) {
      ++counts_.frames_late;
      return FrameAdded::kLate;
    }
    pushBounded(&frames_, t_ns, std::move(frame));
    return FrameAdded::kQueued;
  }

  /// The oldest waiting frame once the IMU has passed its time, else nothing.
  std::optional<Ready> pop() {
    // The newest IMU stamp is 0 before any sample.
    if (frames_.empty() || imu_clock_.newest() <= frames_.front().first) return std::nullopt;
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

  /// How far the IMU's clock jumped back at the last addImu() that returned kNewRun (ns).
  int64_t lastClockJumpNs() const { return last_jump_ns_; }
  std::size_t waitingFrames() const { return frames_.size(); }
  /// Frames on a camera clock that jumped back before the IMU's.
  std::size_t heldFrames() const { return held_.size(); }
  std::size_t waitingImu() const { return imu_.size(); }
  const FrameImuSyncCounts& counts() const { return counts_; }
  const FrameImuSyncOptions& options() const { return options_; }

 private:
  using Queue = std::deque<std::pair<int64_t, Frame>>;

  void pushBounded(Queue* queue, int64_t t_ns, Frame frame) {
    queue->emplace_back(t_ns, std::move(frame));
    if (queue->size() > options_.max_frames) {
      queue->pop_front();
      ++counts_.frames_overflow;
    }
  }

  // Everything from the old clock goes; frames held for the new clock start the new queue.
  void startNewRun() {
    frames_.clear();
    imu_.clear();
    released_any_ = false;
    last_released_ns_ = 0;
    counts_ = FrameImuSyncCounts();
    Queue held;
    held.swap(held_);
    for (auto& [t_ns, frame] : held) {
      if (imu_clock_.laggingOnOldClock(t_ns))
        ++counts_.frames_old_clock;
      else
        frames_.emplace_back(t_ns, std::move(frame));
    }
  }

  FrameImuSyncOptions options_;
  Queue frames_, held_;
  std::deque<ImuSample> imu_;
  bool released_any_ = false;
  int64_t last_released_ns_ = 0;
  int64_t newest_frame_ns_ = 0;  // follows the camera's clock, to see it jump back first
  int64_t last_jump_ns_ = 0;
  ClockWatch imu_clock_;  // the newest IMU stamp, and its jumps back
  FrameImuSyncCounts counts_;
};

}  // namespace alvio
