#include "alvio/logging/run_logger.h"

#include <sstream>

#include "alvio/config/config.h"
#include "alvio/pipeline/offline_runner.h"
#include "alvio/pipeline/vio_pipeline.h"

namespace alvio {

namespace {

std::string join(const std::vector<double>& v) {
  std::ostringstream os;
  for (std::size_t i = 0; i < v.size(); ++i) os << (i ? ", " : "") << v[i];
  return os.str();
}

std::string onOff(bool b) {
  return b ? "on" : "off";
}

// The configuration a reader of the log needs to interpret it.
std::string startupText(const RunInfo& info, const LoggerOptions& lo, const LoggerPaths& paths) {
  const Config& c = info.config;
  std::ostringstream os;
  os << "alvio run\n"
     << "  dataset: " << info.dataset << "\n"
     << "  ground truth: "
     << (info.ground_truth ? std::to_string(info.ground_truth->size()) + " poses" : "none") << "\n"
     << "  config: " << (c.source.empty() ? "(defaults)" : c.source) << "\n"
     << "  output: " << info.out_dir << "\n"
     << "  camera: " << c.camera.camera_model << "/" << c.camera.distortion_model << " "
     << c.camera.width << "x" << c.camera.height << " @ " << c.camera.rate_hz << " Hz, intrinsics ["
     << join(c.camera.intrinsics) << "], distortion [" << join(c.camera.distortion_coefficients)
     << "]\n"
     << "  imu: " << c.imu.rate_hz << " Hz, gyro noise " << c.imu.gyroscope_noise_density
     << ", gyro walk " << c.imu.gyroscope_random_walk << ", acc noise "
     << c.imu.accelerometer_noise_density << ", acc walk " << c.imu.accelerometer_random_walk
     << ", g " << c.imu.gravity_magnitude << "\n"
     << "  points: max " << c.points.max_features << " features, min distance "
     << c.points.min_distance_px << " px\n"
     << "  estimator: window " << c.estimator.window_size << ", keyframe parallax "
     << c.estimator.keyframe_parallax_px << " px, " << c.estimator.max_iterations
     << " iterations, loss " << c.estimator.robust_loss << "\n"
     << "  logger: rawlog " << (paths.rawlog.empty() ? "off" : paths.rawlog) << " (imu "
     << onOff(lo.log_imu) << ", images " << onOff(lo.log_images) << " every " << lo.image_decimation
     << ", poses " << onOff(lo.log_poses) << ", ground truth " << onOff(lo.log_ground_truth)
     << "), scene " << (paths.scene.empty() ? "off" : paths.scene) << " every " << lo.scene_period_s
     << " s, stats every " << lo.stats_period_s << " s";
  return os.str();
}

}  // namespace

RunLogger::RunLogger(const LoggerOptions& options) : options_(options) {
  options_.validate("logger");
  // By default the scene shows the estimator's window lines.
  line_source_ = [](const VioPipeline& pipeline) {
    SceneSegments out;
    for (const auto& l : pipeline.estimator().lineSegments()) out.emplace_back(l.start, l.end);
    return out;
  };
}

RunLogger::~RunLogger() {
  restoreLogSink();
  // logger_'s destructor closes the files of an interrupted run.
}

MapSnapshot RunLogger::snapshot(const Estimator& estimator) {
  MapSnapshot map;
  if (estimator.status() != EstimatorStatus::kTracking) return map;
  for (const auto& s : estimator.windowStates()) {
    StampedPose p;
    p.t = s.t;
    p.p = s.p;
    p.q = s.q;
    map.keyframes.push_back(p);
  }
  for (const auto& [id, p] : estimator.landmarkPositions()) map.points.push_back(p);
  return map;
}

MapSnapshot RunLogger::snapshotOf(const VioPipeline& pipeline) const {
  MapSnapshot map = snapshot(pipeline.estimator());
  if (line_source_) map.lines = line_source_(pipeline);
  return map;
}

void RunLogger::onStart(const RunInfo& info) {
  restoreLogSink();
  logger_.reset();  // a previous run's files are closed first
  pipeline_ = nullptr;
  logger_ = std::make_unique<MrptLogger>(options_, info.config.camera, info.out_dir);
  ground_truth_ = info.ground_truth ? *info.ground_truth : Trajectory();
  next_ground_truth_ = 0;
  logger_->log(LogLevel::kInfo, startupText(info, options_, logger_->paths()));

  // Tee the core's messages: their usual destination, plus the text log.
  previous_sink_ = logSink();
  MrptLogger* logger = logger_.get();
  LogSink previous = previous_sink_;
  setLogSink([previous, logger](LogLevel level, const std::string& message) {
    if (previous)
      previous(level, message);
    else
      logToStderr(level, message);
    logger->log(level, message);
  });
  sink_installed_ = true;
}

void RunLogger::onImu(const ImuSample& sample) {
  if (!logger_) return;
  // Ground truth goes in with the IMU stream, so the rawlog stays in time order.
  const double t = sample.t();
  while (next_ground_truth_ < ground_truth_.size() && ground_truth_[next_ground_truth_].t <= t)
    logger_->addGroundTruth(ground_truth_[next_ground_truth_++]);
  logger_->addImu(sample);
}

void RunLogger::onFrame(const FrameView& frame) {
  if (!logger_) return;
  pipeline_ = &frame.pipeline;
  const PipelineOutput& out = frame.output;
  const double t = nsToSec(frame.t_ns);
  // Initialisation, waiting reasons, failures and resets reach the text log as the core's
  // own messages (through the log sink), so the events are not logged twice here.
  logger_->addImage(frame.t_ns, frame.image);
  if (out.has_pose) {
    StampedPose p;
    p.t = out.state.t;
    p.p = out.state.p;
    p.q = out.state.q;
    logger_->addPose(p);
  }
  FrameStats stats;
  stats.t = t;
  stats.tracked_points = static_cast<int>(out.features.points.size());
  stats.window_landmarks = static_cast<int>(frame.pipeline.estimator().points().landmarks().size());
  stats.pipeline_ms = out.timing.total();
  stats.tracking = out.has_pose;
  logger_->addFrameStats(stats);
  if (logger_->sceneDue(t)) logger_->writeScene(t, snapshotOf(frame.pipeline));
}

void RunLogger::onFinish(const RunResult& result) {
  if (!logger_) return;
  logger_->flushStats();
  std::ostringstream os;
  os << "run finished: " << result.frames << " frames, " << result.poses << " poses, "
     << result.resets << " resets, " << result.skipped_images << " skipped images";
  if (result.evaluation) os << ", ATE RMSE " << result.evaluation->ate_translation_m.rmse << " m";
  logger_->log(LogLevel::kInfo, os.str());
  restoreLogSink();
  const MapSnapshot map = pipeline_ ? snapshotOf(*pipeline_) : MapSnapshot();
  logger_->finish(&map);
  pipeline_ = nullptr;
}

void RunLogger::restoreLogSink() {
  if (!sink_installed_) return;
  setLogSink(previous_sink_);
  previous_sink_ = nullptr;
  sink_installed_ = false;
}

}  // namespace alvio
