#pragma once
// The covariance published with the odometry (nav_msgs/Odometry): an error model calibrated
// on the benchmark's renderings (scripts/odometry_error.py), not the window's own marginal
// covariance. That one would cost a second factorisation a frame, and its position and yaw
// are a gauge the window barely constrains. Position and yaw are relative to where the
// odometry started, so their error grows with the path travelled; roll, pitch and the
// velocity are observed through gravity and stay bounded. A reset of the estimator re-anchors
// the output on the IMU's dead reckoning through the outage, whose error the path does not
// measure: each one adds its own sigma to position and yaw.

#include <array>
#include <string>

#include <Eigen/Core>

namespace alvio {

class YamlReader;

struct OdometryCovarianceOptions {
  // Defaults: config/euroc.yaml's (the synthetic IMU's).
  /// Position, 1 sigma per axis: sqrt(position_sigma_m^2 + (position_drift * path)^2).
  double position_sigma_m = 0.02;
  double position_drift = 0.00063;  ///< m of sigma per m travelled
  double tilt_sigma_deg = 0.11;     ///< roll and pitch, 1 sigma
  /// Yaw, 1 sigma: sqrt(yaw_sigma_deg^2 + (yaw_drift_deg_per_m * path)^2).
  double yaw_sigma_deg = 0.067;
  double yaw_drift_deg_per_m = 0.0023;
  /// Added in quadrature to position and yaw per reset of the estimator, for the rest of
  /// the run: sqrt(sigma^2 + (drift * path)^2 + resets * reset_sigma^2).
  double reset_position_sigma_m = 0.0;
  double reset_yaw_sigma_deg = 0.0;
  // Body frame, per axis (x, y, z); in the file one number for all three or a list of three.
  // A gyroscope on a vibrating body is noisier on some axes (EuRoC's y: 4.7x its x).
  Eigen::Vector3d velocity_sigma_mps = Eigen::Vector3d::Constant(0.006);       ///< linear velocity
  Eigen::Vector3d angular_rate_sigma_rps = Eigen::Vector3d::Constant(0.0025);  ///< angular rate

  /// Reads the keys under `prefix` ("odometry_covariance"); every key is optional. Throws
  /// alvio::Error naming the key on a bad value.
  static OdometryCovarianceOptions load(const YamlReader& yaml, const std::string& prefix);
  /// Throws alvio::Error naming `where` and the key unless every sigma is finite and >= 0.
  void validate(const std::string& where) const;
};

/// Row-major 6x6, as nav_msgs/Odometry's covariance fields.
using Covariance6 = std::array<double, 36>;

class OdometryCovariance {
 public:
  explicit OdometryCovariance(const OdometryCovarianceOptions& options) : options_(options) {}

  /// Adds the step from the last output position to the path travelled.
  void addPosition(const Eigen::Vector3d& p);
  /// The estimator reset (tracking lost): the output goes on from the IMU's dead reckoning.
  /// One before the first output (while initialising) re-anchors nothing and is not counted.
  void addEstimatorReset() { resets_ += has_position_ ? 1 : 0; }
  /// A new run (the clock went back): the path and the resets count from zero again.
  void startNewRun();
  double pathLength() const { return path_m_; }
  int resets() const { return resets_; }

  /// (x, y, z, rotation about the world's x, y, z): the pose's order in nav_msgs/Odometry.
  /// The world's z is along gravity, so x and y are tilt and z is yaw.
  Covariance6 pose() const;
  /// (linear, angular velocity), both in the body frame, as the odometry's twist.
  Covariance6 twist() const;

 private:
  OdometryCovarianceOptions options_;
  double path_m_ = 0.0;
  int resets_ = 0;
  bool has_position_ = false;
  Eigen::Vector3d last_p_ = Eigen::Vector3d::Zero();
};

}  // namespace alvio
