#include "alvio/config/config.h"

#include <cstdlib>

#include "alvio/common/resource_path.h"
#include "alvio/config/yaml_overlay.h"
#include "alvio/config/yaml_reader.h"

namespace alvio {

Config Config::load(const std::string& path) {
  return load(YamlReader::fromString(readConfigText(path), path));
}

Config Config::load(const YamlReader& yaml) {
  Config c;
  c.source = yaml.path();
  c.camera = CameraOptions::load(yaml, "camera");
  c.imu = ImuOptions::load(yaml, "imu");
  c.topics = TopicOptions::load(yaml, "topics");
  c.points = PointTrackerOptions::load(yaml, "points");
  c.estimator = EstimatorOptions::load(yaml, "estimator");
  c.lines = LineTrackerOptions::load(yaml, "lines");
  c.logger = LoggerOptions::load(yaml, "logger");
  yaml.markKnown("mapping");  // read by alvio_mapping (MappingOptions::load)
  yaml.warnUnknownKeys();
  return c;
}

std::string Config::defaultPath() {
  if (const char* env = std::getenv("ALVIO_CONFIG")) return env;
  return findPackageFile("config/euroc.yaml");
}

}  // namespace alvio
