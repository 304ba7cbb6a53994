#include "alvio/pipeline/vio_pipeline.h"

namespace alvio {

VioPipeline::VioPipeline(const Config& config)
    : config_(config),
      camera_(CameraModel::create(config.camera)),
      point_tracker_(config.points, camera_),
      line_tracker_(config.estimator.use_lines ? createLineTracker(config.camera, config.lines)
                                               : nullptr),
      estimator_(config.estimator, config.camera, config.imu) {}

PipelineOutput VioPipeline::addImage(const cv::Mat& gray, int64_t t_ns) {
  PipelineOutput out;
  out.timing.t = t_ns * 1e-9;
  out.features = point_tracker_.track(gray, t_ns, &out.timing);
  if (line_tracker_) {
    LineFrame lines = line_tracker_->track(gray, t_ns * 1e-9);
    out.features.lines = std::move(lines.lines);
    out.features.line_stats = lines.stats;
    out.timing.add("line_detection", lines.stats.undistort_ms + lines.stats.detect_ms);
    out.timing.add("line_tracking", lines.stats.track_ms);
  }
  const int resets_before = estimator_.resetCount();
  out.has_pose = estimator_.addFrame(out.features, &out.timing);
  // After a reset the tracks start again, so re-initialisation sees fresh parallax.
  if (estimator_.resetCount() != resets_before) point_tracker_.reset();
  out.status = estimator_.status();
  if (out.has_pose) {
    out.state = estimator_.latestState();
    out.optimization = estimator_.lastOptimizationStats();
  }
  out.events = estimator_.takeEvents();
  out.retired_lines = estimator_.takeRetiredLines();
  out.window_records = estimator_.takeWindowRecords();
  return out;
}

}  // namespace alvio
