#pragma once
// The whole configuration of a run: one YAML file, one struct per component.
// Every program (offline runner, simulator, nodelets) loads it the same way.

#include <string>

#include "alvio/config/logger_options.h"
#include "alvio/config/sensor_options.h"
#include "alvio/estimator/estimator_options.h"
#include "alvio/frontend/point_tracker_options.h"
#include "alvio/lines/line_tracker_options.h"
#include "alvio/pipeline/odometry_covariance.h"

namespace alvio {

class YamlReader;

struct Config {
  std::string source;  ///< the file it was loaded from ("" for defaults)
  CameraOptions camera;
  ImuOptions imu;
  TopicOptions topics;
  PointTrackerOptions points;
  EstimatorOptions estimator;
  LineTrackerOptions lines;
  LoggerOptions logger;
  OdometryCovarianceOptions odometry_covariance;

  /// Load and validate `path`. Missing/malformed keys throw alvio::Error naming
  /// file and key; unknown keys are logged as warnings.
  static Config load(const std::string& path);
  /// The same from YAML already read (e.g. a file with ROS parameter overrides merged in);
  /// `source` becomes yaml.path().
  static Config load(const YamlReader& yaml);
  /// The YAML of the file `path` with its `base:` files merged in, as load(path) reads it: for
  /// callers that also read other sections (e.g. MappingOptions) from the same file.
  static YamlReader readYaml(const std::string& path);
  /// The configuration shipped as config/euroc.yaml, found next to the sources or installed.
  static std::string defaultPath();
};

}  // namespace alvio
