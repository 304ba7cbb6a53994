#pragma once
// Options of the MRPT run logger (config section "logger"): what it records and
// where. Plain data, no MRPT: the logger itself lives in mapping/ (alvio_logging).

#include <string>

#include "alvio/common/logging.h"

namespace alvio {

class YamlReader;

struct LoggerOptions {
  bool enabled = true;  ///< the offline runner logs unless this is false (or --no-log)
  /// Output folder; "" means the run's output folder.
  std::string out_dir;
  /// Base name: <name>.rawlog, <name>_Images/, <name>.3Dscene.
  std::string name = "alvio";

  // .rawlog contents.
  bool log_imu = true;           ///< CObservationIMU per sample
  bool log_images = true;        ///< CObservationImage, PNG in <name>_Images/
  int image_decimation = 10;     ///< every n-th image (1: all)
  bool log_poses = true;         ///< estimated body pose per frame (CObservationRobotPose)
  bool log_ground_truth = true;  ///< dataset ground truth, own sensor label

  // .3Dscene snapshots.
  bool scenes = true;
  double scene_period_s = 5.0;        ///< dataset time between snapshots; <= 0: only at the end
  bool keep_scene_snapshots = false;  ///< also keep every snapshot in <name>_scenes/

  // Text log (mrpt::system::COutputLogger).
  bool text_log = true;
  std::string text_file = "alvio.log";
  std::string text_level = "info";  ///< debug | info | warn | error
  double stats_period_s = 1.0;      ///< dataset time between throughput/feature-count lines

  /// Read the keys under `prefix` ("logger"); every key is optional. Throws alvio::Error
  /// naming the key on a bad value.
  static LoggerOptions load(const YamlReader& yaml, const std::string& prefix);
  /// Throws alvio::Error naming `where` and the field when a value is out of range.
  void validate(const std::string& where) const;
  /// text_level as a LogLevel (validated).
  LogLevel textLevel() const;
};

/// "debug" | "info" | "warn" | "error" -> LogLevel; throws alvio::Error otherwise.
LogLevel parseLogLevel(const std::string& name);

}  // namespace alvio
