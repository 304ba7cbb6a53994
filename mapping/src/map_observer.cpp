#include "alvio/mapping/map_observer.h"

#include "alvio/common/logging.h"
#include "alvio/pipeline/offline_runner.h"
#include "alvio/pipeline/vio_pipeline.h"

namespace alvio {

MapObserver::MapObserver(const MappingOptions& options, const Eigen::Isometry3d& T_b_c)
    : T_b_c_(T_b_c), map_(options), feed_(T_b_c) {}

void MapObserver::onStart(const RunInfo& info) {
  out_dir_ = info.out_dir;
}

void MapObserver::onFrame(const FrameView& frame) {
  pipeline_ = &frame.pipeline;
  const PipelineOutput& out = frame.output;
  if (!out.has_pose) return;
  map_.addTrajectoryPose({out.state.t, out.state.p, out.state.q});
  if (auto keyframe = feed_.poll(frame.pipeline.estimator())) map_.addKeyframe(*keyframe);
  // Retired lines enter the map seen from the current camera.
  if (!out.retired_lines.empty())
    map_.addKeyframe(retiredLinesKeyframe(out.state, T_b_c_, out.retired_lines));
}

void MapObserver::onFinish(const RunResult&) {
  if (pipeline_)
    for (const KeyframeLandmarks& keyframe : feed_.flush(pipeline_->estimator()))
      map_.addKeyframe(keyframe);
  if (out_dir_.empty()) return;
  files_ = map_.save(out_dir_);
  logInfo("map written to ", out_dir_);
}

}  // namespace alvio
