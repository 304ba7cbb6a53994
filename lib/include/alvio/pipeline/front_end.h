#pragma once
// The visual front end of the pipeline: point tracking (KLT) and, when lines are
// on, line detection and tracking, one grey image in and one FeatureFrame out.
// VioPipeline runs it in line with the estimator; the tracker nodelet runs it in
// its own thread and hands the frame to the estimator nodelet.

#include <memory>
#include <opencv2/core.hpp>

#include "alvio/camera/camera_model.h"
#include "alvio/common/timing.h"
#include "alvio/config/config.h"
#include "alvio/frontend/exposure_compensation.h"
#include "alvio/frontend/feature_frame.h"
#include "alvio/frontend/gyro_rotation.h"
#include "alvio/frontend/point_tracker.h"
#include "alvio/lines/line_tracker.h"

namespace alvio {

class FrontEnd {
 public:
  /// Lines are tracked when config.estimator.use_lines is set.
  explicit FrontEnd(const Config& config);

  /// Queue one gyroscope sample: the trackers start their flow where the rotation between two
  /// images moves each feature (points.gyro_flow, lines.flow.gyro_flow). Add the IMU up to (and
  /// one sample beyond) an image's time before tracking it, as the estimator needs it.
  void addImu(const ImuSample& sample) { gyro_.add(sample); }
  /// Track points (and lines) into the next 8-bit grey image. Stage times go to `timing`.
  FeatureFrame track(const cv::Mat& gray, int64_t t_ns, FrameTiming* timing = nullptr);
  /// Forget the gyroscope samples (the IMU clock went back: a new run).
  void clearImu() {
    gyro_.clear();
    prev_t_ns_ = 0;
  }
  /// Start the point tracks afresh (after an estimator reset, so that re-initialisation
  /// sees fresh parallax).
  void resetPoints() { point_tracker_.reset(); }
  /// Whether the estimator is tracking (initialised): the corners' anchors may act on it.
  void setEstimatorTracking(bool tracking) { point_tracker_.setEstimatorTracking(tracking); }

  const CameraModel& camera() const { return *camera_; }
  std::shared_ptr<const CameraModel> cameraPtr() const { return camera_; }
  bool tracksLines() const { return line_tracker_ != nullptr; }

 private:
  std::shared_ptr<const CameraModel> camera_;
  ExposureCompensation exposure_;
  cv::Mat compensated_;
  PointTracker point_tracker_;
  std::unique_ptr<LineTracker> line_tracker_;  // null when lines are off
  GyroRotation gyro_;
  int64_t prev_t_ns_ = 0;
  bool lines_own_thread_;
};

}  // namespace alvio
