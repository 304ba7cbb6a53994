#pragma once
// The whole offline/online pipeline in one object: images and IMU in, poses
// out. Used by the offline runner; the nodelets split the same parts across
// the tracker and estimator nodelets.

#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "alvio/camera/camera_model.h"
#include "alvio/common/log_throttle.h"
#include "alvio/common/timing.h"
#include "alvio/config/config.h"
#include "alvio/estimator/estimator.h"
#include "alvio/pipeline/front_end.h"

namespace alvio {

struct PipelineOutput {
  bool has_pose = false;  ///< false until initialised, and on the frame of a reset
  bool dropped = false;   ///< the image was not after the previous one: not processed
  BodyState state;        ///< newest frame, output world frame
  EstimatorStatus status = EstimatorStatus::kInitializing;
  FeatureFrame features;
  FrameTiming timing;
  std::vector<EstimatorEvent> events;
  /// Lines that left the estimator's window on this frame, refined over their whole track.
  LineSegments3 retired_lines;
  /// Sensitivity-analysis records of windows that slid on this frame (record_analysis).
  std::vector<WindowTrackRecord> window_records;
  /// What the optimisation of this frame used (valid when has_pose).
  OptimizationStats optimization;
};

class VioPipeline {
 public:
  explicit VioPipeline(const Config& config);

  /// Queue one IMU sample. The IMU clock decides on clock jumps (it comes straight from the
  /// sensor): after one the estimator has reset and images continue on the new clock.
  /// Returns true when this sample was such a jump.
  bool addImu(const ImuSample& sample);
  /// Track and estimate one 8-bit grey image. IMU up to (and one sample beyond) its time
  /// should have been added. An image not after the previous one is dropped (a stamp
  /// going back would run the tracker and the IMU integration backwards).
  /// `edit_features`, when given, may change the tracked features before the estimator sees
  /// them (alvio_point_truth replaces them with their true projections).
  PipelineOutput addImage(const cv::Mat& gray, int64_t t_ns,
                          const std::function<void(FeatureFrame*)>& edit_features = {});

  std::size_t droppedImages() const { return images_late_.total(); }

  const Estimator& estimator() const { return estimator_; }
  const CameraModel& camera() const { return front_end_.camera(); }

 private:
  Config config_;
  FrontEnd front_end_;
  Estimator estimator_;
  int64_t last_image_ns_ = 0;
  LogThrottle images_late_;
};

}  // namespace alvio
