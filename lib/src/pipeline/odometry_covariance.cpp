#include "alvio/pipeline/odometry_covariance.h"

#include <cmath>
#include <sstream>

#include "alvio/common/angles.h"
#include "alvio/common/error.h"
#include "alvio/config/yaml_reader.h"

namespace alvio {

namespace {

Covariance6 diagonal(const std::array<double, 6>& sigmas) {
  Covariance6 c{};
  for (int i = 0; i < 6; ++i) c[i * 6 + i] = sigmas[i] * sigmas[i];
  return c;
}
}  // namespace

OdometryCovarianceOptions OdometryCovarianceOptions::load(const YamlReader& yaml,
                                                          const std::string& prefix) {
  OdometryCovarianceOptions o;
  const std::string p = prefix + ".";
  o.position_sigma_m = yaml.getDouble(p + "position_sigma_m", o.position_sigma_m);
  o.position_drift = yaml.getDouble(p + "position_drift", o.position_drift);
  o.tilt_sigma_deg = yaml.getDouble(p + "tilt_sigma_deg", o.tilt_sigma_deg);
  o.yaw_sigma_deg = yaml.getDouble(p + "yaw_sigma_deg", o.yaw_sigma_deg);
  o.yaw_drift_deg_per_m = yaml.getDouble(p + "yaw_drift_deg_per_m", o.yaw_drift_deg_per_m);
  // The sixty-sixth session's constant per reset: an outage's error grows with its length.
  for (const char* old : {"reset_position_sigma_m", "reset_yaw_sigma_deg"})
    if (yaml.has(p + old))
      throw Error(yaml.path() + ": " + p + old +
                  " was replaced by outage_position_sigma_mps, outage_position_sigma_mps2 and "
                  "outage_yaw_sigma_deg_per_s (an outage's error grows with its length; "
                  "scripts/odometry_error.py fits them)");
  o.outage_min_s = yaml.getDouble(p + "outage_min_s", o.outage_min_s);
  o.outage_position_sigma_mps =
      yaml.getDouble(p + "outage_position_sigma_mps", o.outage_position_sigma_mps);
  o.outage_position_sigma_mps2 =
      yaml.getDouble(p + "outage_position_sigma_mps2", o.outage_position_sigma_mps2);
  o.outage_yaw_sigma_deg_per_s =
      yaml.getDouble(p + "outage_yaw_sigma_deg_per_s", o.outage_yaw_sigma_deg_per_s);
  o.velocity_sigma_mps = yaml.getPerAxis(p + "velocity_sigma_mps", o.velocity_sigma_mps);
  o.angular_rate_sigma_rps =
      yaml.getPerAxis(p + "angular_rate_sigma_rps", o.angular_rate_sigma_rps);
  o.validate(yaml.path() + ": " + prefix);
  return o;
}

void OdometryCovarianceOptions::validate(const std::string& where) const {
  const auto check = [&](const std::string& key, double value) {
    if (std::isfinite(value) && value >= 0) return;
    std::ostringstream os;
    os << where << "." << key << " must be a finite value >= 0, got " << value;
    throw Error(os.str());
  };
  check("position_sigma_m", position_sigma_m);
  check("position_drift", position_drift);
  check("tilt_sigma_deg", tilt_sigma_deg);
  check("yaw_sigma_deg", yaw_sigma_deg);
  check("yaw_drift_deg_per_m", yaw_drift_deg_per_m);
  check("outage_min_s", outage_min_s);
  check("outage_position_sigma_mps", outage_position_sigma_mps);
  check("outage_position_sigma_mps2", outage_position_sigma_mps2);
  check("outage_yaw_sigma_deg_per_s", outage_yaw_sigma_deg_per_s);
  for (int axis = 0; axis < 3; ++axis) {  // named as the file's list: key[axis]
    const std::string index = "[" + std::to_string(axis) + "]";
    check("velocity_sigma_mps" + index, velocity_sigma_mps[axis]);
    check("angular_rate_sigma_rps" + index, angular_rate_sigma_rps[axis]);
  }
}

void OdometryCovariance::addPose(double t, const Eigen::Vector3d& p) {
  if (!p.allFinite() || !std::isfinite(t)) return;
  if (has_position_) {
    path_m_ += (p - last_p_).norm();
    const double gap = t - last_t_;
    if (gap > options_.outage_min_s) {
      ++outages_;
      outage_s2_ += gap * gap;
      outage_s4_ += gap * gap * gap * gap;
    }
  }
  last_t_ = t;
  last_p_ = p;
  has_position_ = true;
}

void OdometryCovariance::startNewRun() {
  path_m_ = 0.0;
  outages_ = 0;
  outage_s2_ = outage_s4_ = 0.0;
  has_position_ = false;
}

Covariance6 OdometryCovariance::pose() const {
  const OdometryCovarianceOptions& o = options_;
  // sigma^2 + (drift * path)^2, plus each outage's
  const auto grown = [&](double sigma, double drift) {
    return sigma * sigma + std::pow(drift * path_m_, 2);
  };
  const double a = o.outage_position_sigma_mps, b = o.outage_position_sigma_mps2;
  const double position = std::sqrt(grown(o.position_sigma_m, o.position_drift) +
                                    a * a * outage_s2_ + b * b * outage_s4_);
  const double tilt = o.tilt_sigma_deg * kDegToRad;
  const double c = o.outage_yaw_sigma_deg_per_s;
  const double yaw =
      std::sqrt(grown(o.yaw_sigma_deg, o.yaw_drift_deg_per_m) + c * c * outage_s2_) * kDegToRad;
  return diagonal({position, position, position, tilt, tilt, yaw});
}

Covariance6 OdometryCovariance::twist() const {
  const Eigen::Vector3d& v = options_.velocity_sigma_mps;
  const Eigen::Vector3d& w = options_.angular_rate_sigma_rps;
  return diagonal({v.x(), v.y(), v.z(), w.x(), w.y(), w.z()});
}

}  // namespace alvio
