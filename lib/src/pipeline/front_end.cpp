#include "alvio/pipeline/front_end.h"

#include <future>

namespace alvio {

FrontEnd::FrontEnd(const Config& config)
    : camera_(CameraModel::create(config.camera)),
      exposure_(config.points.exposure_jump),
      point_tracker_(config.points, camera_),
      line_tracker_(config.estimator.use_lines ? createLineTracker(config.camera, config.lines)
                                               : nullptr),
      gyro_(config.camera.T_b_c.linear()),
      lines_own_thread_(config.lines.own_thread) {}

FeatureFrame FrontEnd::track(const cv::Mat& gray, int64_t t_ns, FrameTiming* timing) {
  const double mean = cv::mean(gray)[0];
  const cv::Mat& image = exposure_.apply(gray, mean, &compensated_);
  std::optional<Eigen::Matrix3d> R_cur_prev;
  if (prev_t_ns_ != 0) R_cur_prev = gyro_.cameraRotation(prev_t_ns_, t_ns);
  prev_t_ns_ = t_ns;
  gyro_.dropBefore(t_ns);
  // The two trackers share nothing but the (read-only) image.
  std::future<LineFrame> lines_done;
  if (line_tracker_ && lines_own_thread_)
    lines_done = std::async(std::launch::async,
                            [&] { return line_tracker_->track(image, t_ns * 1e-9, R_cur_prev); });
  // The frame records the scene's light, not the compensated level.
  FeatureFrame frame = point_tracker_.track(image, t_ns, timing, mean, R_cur_prev);
  if (line_tracker_) {
    LineFrame lines = lines_done.valid() ? lines_done.get()
                                         : line_tracker_->track(image, t_ns * 1e-9, R_cur_prev);
    frame.lines = std::move(lines.lines);
    frame.line_stats = lines.stats;
    if (timing) {
      timing->add("line_detection", lines.stats.undistort_ms + lines.stats.detect_ms);
      timing->add("line_tracking", lines.stats.track_ms);
    }
  }
  return frame;
}

}  // namespace alvio
