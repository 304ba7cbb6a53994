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
#include "alvio/frontend/point_tracker.h"
#include "alvio/lines/line_tracker.h"

namespace alvio {

class FrontEnd {
 public:
  /// Lines are tracked when config.estimator.use_lines is set.
  explicit FrontEnd(const Config& config);

  /// Track points (and lines) into the next 8-bit grey image. Stage times go to `timing`.
  FeatureFrame track(const cv::Mat& gray, int64_t t_ns, FrameTiming* timing = nullptr);
  /// Start the point tracks afresh (after an estimator reset, so that re-initialisation
  /// sees fresh parallax).
  void resetPoints() { point_tracker_.reset(); }

  const CameraModel& camera() const { return *camera_; }
  std::shared_ptr<const CameraModel> cameraPtr() const { return camera_; }
  bool tracksLines() const { return line_tracker_ != nullptr; }

 private:
  std::shared_ptr<const CameraModel> camera_;
  ExposureCompensation exposure_;
  cv::Mat compensated_;
  PointTracker point_tracker_;
  std::unique_ptr<LineTracker> line_tracker_;  // null when lines are off
  bool lines_own_thread_;
};

}  // namespace alvio
