#include "alvio/pipeline/vio_pipeline.h"

#include "alvio/common/clock_jump.h"
#include "alvio/common/logging.h"

namespace alvio {

VioPipeline::VioPipeline(const Config& config)
    : config_(config),
      front_end_(config),
      estimator_(config.estimator, config.camera, config.imu) {}

bool VioPipeline::addImu(const ImuSample& sample) {
  const int jumps_before = estimator_.clockJumps();
  estimator_.addImu(sample);
  const bool jumped = estimator_.clockJumps() != jumps_before;
  if (jumped) {
    last_image_ns_ = 0;  // the next image starts the new clock
    front_end_.resetPoints();
    front_end_.clearImu();
  }
  front_end_.addImu(sample);
  return jumped;
}

PipelineOutput VioPipeline::addImage(const cv::Mat& gray, int64_t t_ns,
                                     const std::function<void(FeatureFrame*)>& edit_features) {
  PipelineOutput out;
  out.timing.t = t_ns * 1e-9;
  if (staleStamp(t_ns, last_image_ns_)) {
    std::size_t n = 0;
    if (images_late_.shouldLog(t_ns * 1e-9, &n))
      logWarn(n, " image(s) not after the previous one dropped (latest at ", t_ns, " ns, previous ",
              last_image_ns_, " ns)");
    out.dropped = true;
    return out;
  }
  last_image_ns_ = t_ns;
  out.features = front_end_.track(gray, t_ns, &out.timing);
  if (edit_features) edit_features(&out.features);
  const int resets_before = estimator_.resetCount();
  out.has_pose = estimator_.addFrame(out.features, &out.timing);
  // After a reset the tracks start again, so re-initialisation sees fresh parallax.
  if (estimator_.resetCount() != resets_before) front_end_.resetPoints();
  out.status = estimator_.status();
  front_end_.setEstimatorTracking(out.status == EstimatorStatus::kTracking);
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
