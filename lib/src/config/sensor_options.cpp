#include "alvio/config/sensor_options.h"

#include <cmath>
#include <sstream>

#include "alvio/common/error.h"
#include "alvio/config/yaml_reader.h"

namespace alvio {
namespace {
constexpr double kMaxTimeshiftS = 1.0;

void requirePositive(double value, const std::string& where) {
  if (!(value > 0.0) || !std::isfinite(value)) {
    std::ostringstream os;
    os << where << " must be positive, got " << value;
    throw Error(os.str());
  }
}
// "camera" + "rate_hz" -> "camera.rate_hz"; an empty prefix reads top-level keys
// (as in EuRoC's own sensor.yaml).
std::string keyPrefix(const std::string& prefix) {
  return prefix.empty() ? "" : prefix + ".";
}
std::string whereOf(const YamlReader& yaml, const std::string& prefix) {
  return prefix.empty() ? yaml.path() : yaml.path() + ": " + prefix;
}
}  // namespace

CameraOptions CameraOptions::load(const YamlReader& yaml, const std::string& prefix) {
  CameraOptions o;
  const std::string p = keyPrefix(prefix);
  o.camera_model = yaml.getString(p + "camera_model", o.camera_model);
  o.distortion_model = yaml.getString(p + "distortion_model");
  const auto resolution = yaml.getDoubles(p + "resolution", 2);
  // Checked before the conversion to int: a huge value would be undefined behaviour there
  // (found by fuzz_config).
  for (double v : resolution)
    if (!(v >= 1 && v <= 65536) || v != std::floor(v)) {
      std::ostringstream os;
      os << yaml.where(p + "resolution")
         << " must be two whole numbers of pixels in [1, 65536], got " << v;
      throw Error(os.str());
    }
  o.width = static_cast<int>(resolution[0]);
  o.height = static_cast<int>(resolution[1]);
  o.intrinsics = yaml.getDoubles(p + "intrinsics", 4);
  o.distortion_coefficients = yaml.getDoubles(p + "distortion_coefficients");
  o.T_b_c = yaml.getTransform(p + "T_BS");
  o.rate_hz = yaml.getDouble(p + "rate_hz", o.rate_hz);
  o.timeshift_cam_imu = yaml.getDouble(p + "timeshift_cam_imu", o.timeshift_cam_imu);
  // Descriptive keys of EuRoC sensor.yaml that carry no parameters.
  yaml.markKnown(p + "sensor_type");
  yaml.markKnown(p + "comment");
  o.validate(whereOf(yaml, prefix));
  return o;
}

void CameraOptions::validate(const std::string& where) const {
  if (camera_model != "pinhole")
    throw Error(where + ".camera_model: unsupported '" + camera_model + "' (expected 'pinhole')");
  const std::size_t n = distortion_coefficients.size();
  if (distortion_model == "radial-tangential" || distortion_model == "radtan") {
    if (n != 4 && n != 5)
      throw Error(where +
                  ".distortion_coefficients: radial-tangential needs 4 values (k1 k2 p1 p2)"
                  ", got " +
                  std::to_string(n));
  } else if (distortion_model == "equidistant") {
    if (n != 4)
      throw Error(where + ".distortion_coefficients: equidistant needs 4 values (k1..k4), got " +
                  std::to_string(n));
  } else if (distortion_model == "none") {
    if (n != 0) throw Error(where + ".distortion_coefficients: must be empty for model 'none'");
  } else {
    throw Error(where + ".distortion_model: unsupported '" + distortion_model +
                "' (expected radial-tangential, equidistant or none)");
  }
  if (width <= 0 || height <= 0)
    throw Error(where + ".resolution: must be positive, got [" + std::to_string(width) + ", " +
                std::to_string(height) + "]");
  requirePositive(intrinsics[0], where + ".intrinsics[0] (fu)");
  requirePositive(intrinsics[1], where + ".intrinsics[1] (fv)");
  if (intrinsics[2] < 0 || intrinsics[2] > width || intrinsics[3] < 0 || intrinsics[3] > height) {
    std::ostringstream os;
    os << where << ".intrinsics: principal point (" << intrinsics[2] << ", " << intrinsics[3]
       << ") lies outside the " << width << "x" << height << " image";
    throw Error(os.str());
  }
  requirePositive(rate_hz, where + ".rate_hz");
  // Beyond a second it is a clock offset, not a delay: stamp the images on the IMU's clock.
  if (!(std::abs(timeshift_cam_imu) <= kMaxTimeshiftS)) {
    std::ostringstream os;
    os << where << ".timeshift_cam_imu must be within +-" << kMaxTimeshiftS << " s, got "
       << timeshift_cam_imu;
    throw Error(os.str());
  }
}

int64_t CameraOptions::imuClockNs(int64_t camera_stamp_ns) const {
  return camera_stamp_ns + static_cast<int64_t>(std::llround(timeshift_cam_imu * 1e9));
}

ImuOptions ImuOptions::load(const YamlReader& yaml, const std::string& prefix) {
  ImuOptions o;
  const std::string p = keyPrefix(prefix);
  o.gyroscope_noise_density = yaml.getDouble(p + "gyroscope_noise_density");
  o.gyroscope_random_walk = yaml.getDouble(p + "gyroscope_random_walk");
  o.accelerometer_noise_density = yaml.getDouble(p + "accelerometer_noise_density");
  o.accelerometer_random_walk = yaml.getDouble(p + "accelerometer_random_walk");
  o.rate_hz = yaml.getDouble(p + "rate_hz", o.rate_hz);
  o.gravity_magnitude = yaml.getDouble(p + "gravity_magnitude", o.gravity_magnitude);
  yaml.markKnown(p + "sensor_type");
  yaml.markKnown(p + "comment");
  // The IMU defines the body frame; a T_BS here must be identity.
  if (yaml.has(p + "T_BS")) {
    const Eigen::Isometry3d T = yaml.getTransform(p + "T_BS");
    if (!T.isApprox(Eigen::Isometry3d::Identity(), 1e-9))
      throw Error(yaml.where(p + "T_BS") + " must be identity: the IMU frame is the body frame");
  }
  o.validate(whereOf(yaml, prefix));
  return o;
}

void ImuOptions::validate(const std::string& where) const {
  requirePositive(gyroscope_noise_density, where + ".gyroscope_noise_density");
  requirePositive(gyroscope_random_walk, where + ".gyroscope_random_walk");
  requirePositive(accelerometer_noise_density, where + ".accelerometer_noise_density");
  requirePositive(accelerometer_random_walk, where + ".accelerometer_random_walk");
  requirePositive(rate_hz, where + ".rate_hz");
  requirePositive(gravity_magnitude, where + ".gravity_magnitude");
}

TopicOptions TopicOptions::load(const YamlReader& yaml, const std::string& prefix) {
  TopicOptions o;
  o.image = yaml.getString(keyPrefix(prefix) + "image", o.image);
  o.imu = yaml.getString(keyPrefix(prefix) + "imu", o.imu);
  return o;
}

}  // namespace alvio
