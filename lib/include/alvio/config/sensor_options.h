#pragma once
// Sensor calibration options, EuRoC-style (the keys of EuRoC's sensor.yaml).

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

namespace alvio {

class YamlReader;

struct CameraOptions {
  /// "pinhole" is the only projection; the distortion model picks the variant.
  std::string camera_model = "pinhole";
  /// "radial-tangential" (k1 k2 p1 p2) or "equidistant" (k1 k2 k3 k4, Kannala-Brandt).
  std::string distortion_model = "radial-tangential";
  int width = 752;
  int height = 480;
  /// fu, fv, cu, cv in pixels.
  std::vector<double> intrinsics = {458.654, 457.296, 367.215, 248.375};
  std::vector<double> distortion_coefficients = {-0.28340811, 0.07395907, 0.00019359,
                                                 1.76187114e-05};
  /// Camera pose in the body (IMU) frame: EuRoC's T_BS.
  Eigen::Isometry3d T_b_c = Eigen::Isometry3d::Identity();
  double rate_hz = 20.0;
  /// Kalibr's timeshift_cam_imu (s): an image stamped t_cam was taken at t_cam + shift on the
  /// IMU's clock. The pipeline works on the IMU's clock, so its outputs are stamped on it.
  double timeshift_cam_imu = 0.0;

  /// The time of an image stamped `camera_stamp_ns`, on the IMU's clock.
  int64_t imuClockNs(int64_t camera_stamp_ns) const;

  /// Read the keys under `prefix` ("camera"); throws alvio::Error naming the key.
  static CameraOptions load(const YamlReader& yaml, const std::string& prefix);
  /// Throws alvio::Error when values are inconsistent (sizes, signs).
  void validate(const std::string& where) const;
};

struct ImuOptions {
  double gyroscope_noise_density = 1.6968e-04;     ///< rad/s/sqrt(Hz)
  double gyroscope_random_walk = 1.9393e-05;       ///< rad/s^2/sqrt(Hz)
  double accelerometer_noise_density = 2.0000e-3;  ///< m/s^2/sqrt(Hz)
  double accelerometer_random_walk = 3.0000e-3;    ///< m/s^3/sqrt(Hz)
  double rate_hz = 200.0;
  double gravity_magnitude = 9.81;  ///< m/s^2

  static ImuOptions load(const YamlReader& yaml, const std::string& prefix);
  void validate(const std::string& where) const;
};

struct TopicOptions {
  std::string image = "/cam0/image_raw";
  std::string imu = "/imu0";

  static TopicOptions load(const YamlReader& yaml, const std::string& prefix);
};

}  // namespace alvio
