#include "alvio/config/logger_options.h"

#include <cmath>

#include "alvio/common/error.h"
#include "alvio/config/yaml_reader.h"

namespace alvio {

LogLevel parseLogLevel(const std::string& name) {
  if (name == "debug") return LogLevel::kDebug;
  if (name == "info") return LogLevel::kInfo;
  if (name == "warn") return LogLevel::kWarn;
  if (name == "error") return LogLevel::kError;
  throw Error("unknown log level '" + name + "' (expected debug, info, warn or error)");
}

LoggerOptions LoggerOptions::load(const YamlReader& yaml, const std::string& prefix) {
  LoggerOptions o;
  const std::string p = prefix + ".";
  o.enabled = yaml.getBool(p + "enabled", o.enabled);
  o.out_dir = yaml.getString(p + "out_dir", o.out_dir);
  o.name = yaml.getString(p + "name", o.name);
  o.log_imu = yaml.getBool(p + "log_imu", o.log_imu);
  o.log_images = yaml.getBool(p + "log_images", o.log_images);
  o.image_decimation = yaml.getInt(p + "image_decimation", o.image_decimation);
  o.log_poses = yaml.getBool(p + "log_poses", o.log_poses);
  o.log_ground_truth = yaml.getBool(p + "log_ground_truth", o.log_ground_truth);
  o.scenes = yaml.getBool(p + "scenes", o.scenes);
  o.scene_period_s = yaml.getDouble(p + "scene_period_s", o.scene_period_s);
  o.keep_scene_snapshots = yaml.getBool(p + "keep_scene_snapshots", o.keep_scene_snapshots);
  o.text_log = yaml.getBool(p + "text_log", o.text_log);
  o.text_file = yaml.getString(p + "text_file", o.text_file);
  o.text_level = yaml.getString(p + "text_level", o.text_level);
  o.stats_period_s = yaml.getDouble(p + "stats_period_s", o.stats_period_s);
  o.validate(yaml.path() + ": " + prefix);
  return o;
}

void LoggerOptions::validate(const std::string& where) const {
  if (name.empty() || name.find('/') != std::string::npos)
    throw Error(where + ".name must be a non-empty file name without '/', got '" + name + "'");
  if (image_decimation < 1)
    throw Error(where + ".image_decimation must be at least 1, got " +
                std::to_string(image_decimation));
  if (!std::isfinite(scene_period_s))
    throw Error(where + ".scene_period_s must be a number of seconds");
  if (!(stats_period_s > 0) || !std::isfinite(stats_period_s))
    throw Error(where + ".stats_period_s must be positive, got " + std::to_string(stats_period_s));
  if (text_log && text_file.empty()) throw Error(where + ".text_file must not be empty");
  try {
    parseLogLevel(text_level);
  } catch (const Error& e) {
    throw Error(where + ".text_level: " + e.what());
  }
}

LogLevel LoggerOptions::textLevel() const {
  return parseLogLevel(text_level);
}

}  // namespace alvio
