#include "alvio/mapping/map_observer.h"

#include "alvio/common/logging.h"
#include "alvio/pipeline/offline_runner.h"
#include "alvio/pipeline/vio_pipeline.h"

namespace alvio {

MapObserver::MapObserver(const MappingOptions& options, const Eigen::Isometry3d& T_b_c)
    : options_(options), T_b_c_(T_b_c), map_(options), feed_(T_b_c) {}

void MapObserver::onStart(const RunInfo& info) {
  out_dir_ = info.out_dir;
}

void MapObserver::onFrame(const FrameView& frame) {
  pipeline_ = &frame.pipeline;
  const PipelineOutput& out = frame.output;
  if (!out.has_pose) return;
  map_.addTrajectoryPose({out.state.t, out.state.p, out.state.q});
  if (auto keyframe = feed_.poll(frame.pipeline.estimator())) map_.addKeyframe(*keyframe);
  if (out.retired_lines.empty()) return;
  // Retired lines enter the map seen from the current camera.
  KeyframeLandmarks lines;
  lines.t = out.state.t;
  lines.T_w_c = Eigen::Translation3d(out.state.p) * out.state.q * T_b_c_;
  for (const auto& l : out.retired_lines) {
    if (l.direction_std_deg < 0 || l.direction_std_deg > options_.max_line_direction_std_deg)
      continue;
    lines.lines.push_back({l.id, l.start, l.end, l.observations});
  }
  if (!lines.lines.empty()) map_.addKeyframe(lines);
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
