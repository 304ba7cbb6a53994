#include "alvio/config/config.h"

#include <cstdlib>
#include <sstream>

#include "alvio/common/error.h"
#include "alvio/common/resource_path.h"
#include "alvio/config/yaml_overlay.h"
#include "alvio/config/yaml_reader.h"

namespace alvio {

namespace {
// A surface is a polynomial over positions normalised by the image size it was fitted on:
// applied to another camera it would select features by nonsense.
void checkSurfacesFitCamera(const Config& c, const YamlReader& yaml) {
  const FeatureSelectionOptions& s = c.estimator.selection;
  for (const TrackSurface* surface : {&s.point_surface, &s.line_surface}) {
    if (!surface->valid()) continue;
    if (surface->width == c.camera.width && surface->height == c.camera.height) continue;
    std::ostringstream os;
    os << yaml.where("estimator.selection.surfaces_file") << ": '" << s.surfaces_file
       << "' was fitted on " << surface->width << "x" << surface->height
       << " images, but camera.resolution is [" << c.camera.width << ", " << c.camera.height
       << "]: run alvio analyze on records of this camera";
    throw Error(os.str());
  }
}
}  // namespace

YamlReader Config::readYaml(const std::string& path) {
  return YamlReader::fromString(readConfigText(path), path);
}

Config Config::load(const std::string& path) {
  return load(readYaml(path));
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
  c.odometry_covariance = OdometryCovarianceOptions::load(yaml, "odometry_covariance");
  checkSurfacesFitCamera(c, yaml);
  yaml.markKnown("mapping");  // read by alvio_mapping (MappingOptions::load)
  yaml.warnUnknownKeys();
  return c;
}

std::string Config::defaultPath() {
  if (const char* env = std::getenv("ALVIO_CONFIG")) return env;
  return findPackageFile("config/euroc.yaml");
}

}  // namespace alvio
