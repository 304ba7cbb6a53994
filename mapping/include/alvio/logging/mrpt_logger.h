#pragma once
// The GUI-less MRPT logger of a run: a .rawlog (IMU, decimated images, estimated
// and ground-truth body poses, data timestamps), .3Dscene snapshots (trajectories,
// window points, 3D lines, keyframe frustums) and a levelled text log. It has no
// ROS and no display dependency, and its header no MRPT one (pimpl), so the
// offline runner, tools and the logger nodelet can all include it cheaply.
//
// Data may arrive slightly out of time order (frames are logged when the
// pipeline is done with them, after later IMU samples): the rawlog is written
// in time order through a short reorder buffer. It is streamed into X.rawlog.part and
// renamed to X.rawlog by finish(), and scenes are replaced by rename, so a run that is
// killed never leaves a half-written file under the final names.
//
// Threads: log() may be called from any thread; everything else from one thread
// at a time (the offline runner's, or a nodelet's serialised callbacks).

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "alvio/common/logging.h"
#include "alvio/common/types.h"
#include "alvio/config/logger_options.h"
#include "alvio/config/sensor_options.h"

namespace alvio {

/// A 3D line segment (two end points, world frame), as the line map hands it over.
using SceneSegment = std::pair<Eigen::Vector3d, Eigen::Vector3d>;
using SceneSegments = std::vector<SceneSegment>;

/// The estimator's map at one instant, output world frame.
struct MapSnapshot {
  Trajectory keyframes;                 ///< T_w_b of the window frames, oldest first
  std::vector<Eigen::Vector3d> points;  ///< triangulated window landmarks
  SceneSegments lines;                  ///< 3D line landmarks
};

/// Per-frame numbers for the periodic throughput line of the text log.
struct FrameStats {
  double t = 0;              ///< frame time (s, data time)
  int tracked_points = 0;    ///< features the front end tracked/detected
  int window_landmarks = 0;  ///< landmarks the estimator holds
  double pipeline_ms = 0;    ///< pipeline time of the frame
  bool tracking = false;     ///< estimator initialised
};

/// Where the logger writes; empty when that output is switched off.
struct LoggerPaths {
  std::string rawlog, images_dir, scene, scenes_dir, text;
};

/// What has been written so far.
struct LoggerCounts {
  std::size_t imu = 0, images = 0, poses = 0, ground_truth = 0, scenes = 0, text_lines = 0;
};

class MrptLogger {
 public:
  /// Sensor labels in the rawlog.
  static constexpr const char* kImuLabel = "IMU";
  static constexpr const char* kCameraLabel = "CAMERA0";
  static constexpr const char* kPoseLabel = "VIO_POSE";
  static constexpr const char* kGroundTruthLabel = "GROUND_TRUTH";

  /// Opens the files `options` asks for under `out_dir` (created if needed; options.out_dir,
  /// when set, takes precedence). `camera` gives the image observations their calibration
  /// and the frustums their shape. Throws alvio::Error when a file cannot be opened.
  MrptLogger(const LoggerOptions& options, const CameraOptions& camera, const std::string& out_dir);
  /// Calls finish() without a final map if it was not called.
  ~MrptLogger();
  MrptLogger(const MrptLogger&) = delete;
  MrptLogger& operator=(const MrptLogger&) = delete;

  const LoggerOptions& options() const;
  const LoggerPaths& paths() const;
  LoggerCounts counts() const;

  /// A line in the text log (no-op when the text log is off or below its level).
  void log(LogLevel level, const std::string& message);

  // Rawlog. Times are data times; nothing here reads the wall clock.
  void addImu(const ImuSample& sample);
  void addGroundTruth(const StampedPose& T_w_b);
  /// Counts every image and keeps every image_decimation-th one (PNG in <name>_Images/).
  void addImage(int64_t t_ns, const cv::Mat& image);
  /// The estimated body pose of a frame; also extends the scene's trajectory.
  void addPose(const StampedPose& T_w_b);

  /// One processed frame for the periodic throughput/feature-count line.
  void addFrameStats(const FrameStats& stats);
  /// Write the throughput line of the frames since the last one now (end of a run).
  void flushStats();

  /// Whether a scene snapshot is due at data time t (scene_period_s elapsed).
  bool sceneDue(double t) const;
  /// Write the scene with `map` now (atomically: temp file, then rename).
  void writeScene(double t, const MapSnapshot& map);

  /// Flush the reorder buffer, write the last scene (when `final_map` is given and scenes
  /// are on) and close every file. Idempotent; later add* calls are ignored.
  void finish(const MapSnapshot* final_map = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace alvio
