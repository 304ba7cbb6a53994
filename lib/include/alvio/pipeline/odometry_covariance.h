#pragma once
// The covariance published with the odometry (nav_msgs/Odometry): an error model calibrated
// on the benchmark's renderings (scripts/odometry_error.py), not the window's own marginal
// covariance. That one would cost a second factorisation a frame, and its position and yaw
// are a gauge the window barely constrains. Position and yaw are relative to where the
// odometry started, so their error grows with the path travelled; roll, pitch and the
// velocity are observed through gravity and stay bounded. An outage (a pause in the output:
// images missing, tracking lost, a reset and the new initialisation) is bridged by the IMU's
// dead reckoning, whose error the path does not measure and which grows with the outage's
// length: each one adds its own sigma to position and yaw.

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
  /// A pause in the output longer than this is an outage (at 20 Hz: 6 frames missing).
  double outage_min_s = 0.3;
  /// Added in quadrature per outage of T s, for the rest of the run: to the position
  /// (a T)^2 + (b T^2)^2 per axis, a the velocity's error carried through the outage and b
  /// the acceleration's (mostly gravity's, through the tilt's error); to the yaw (c T)^2.
  double outage_position_sigma_mps = 0.0;   ///< a, m per s of outage
  double outage_position_sigma_mps2 = 0.0;  ///< b, m per s^2 of outage
  double outage_yaw_sigma_deg_per_s = 0.0;  ///< c
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

  /// The output pose at time t (s): adds the step from the last one to the path travelled,
  /// and the time since it, when longer than outage_min_s, as an outage.
  void addPose(double t, const Eigen::Vector3d& p);
  /// A new run (the clock went back): the path and the outages count from zero again.
  void startNewRun();
  double pathLength() const { return path_m_; }
  int outages() const { return outages_; }

  /// (x, y, z, rotation about the world's x, y, z): the pose's order in nav_msgs/Odometry.
  /// The world's z is along gravity, so x and y are tilt and z is yaw.
  Covariance6 pose() const;
  /// (linear, angular velocity), both in the body frame, as the odometry's twist.
  Covariance6 twist() const;

 private:
  OdometryCovarianceOptions options_;
  double path_m_ = 0.0;
  int outages_ = 0;
  double outage_s2_ = 0.0, outage_s4_ = 0.0;  // sums of T^2 and T^4 over the outages
  bool has_position_ = false;
  double last_t_ = 0.0;
  Eigen::Vector3d last_p_ = Eigen::Vector3d::Zero();
};

}  // namespace alvio
