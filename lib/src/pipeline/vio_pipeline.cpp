#include "alvio/pipeline/vio_pipeline.h"

namespace alvio {

VioPipeline::VioPipeline(const Config& config)
    : config_(config),
      front_end_(config),
      estimator_(config.estimator, config.camera, config.imu) {}

PipelineOutput VioPipeline::addImage(const cv::Mat& gray, int64_t t_ns) {
  PipelineOutput out;
  out.timing.t = t_ns * 1e-9;
  out.features = front_end_.track(gray, t_ns, &out.timing);
  const int resets_before = estimator_.resetCount();
  out.has_pose = estimator_.addFrame(out.features, &out.timing);
  // After a reset the tracks start again, so re-initialisation sees fresh parallax.
  if (estimator_.resetCount() != resets_before) front_end_.resetPoints();
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
