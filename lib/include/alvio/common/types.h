#pragma once
// Plain data types shared by the whole core. Time is int64 nanoseconds in
// sensor records (as EuRoC stores it) and double seconds in trajectories.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace alvio {

inline double nsToSec(int64_t ns) {
  return static_cast<double>(ns) * 1e-9;
}
inline int64_t secToNs(double s) {
  return static_cast<int64_t>(std::llround(s * 1e9));
}

/// One IMU sample in the body frame: angular rate (rad/s) and specific force (m/s^2).
struct ImuSample {
  int64_t t_ns = 0;
  Eigen::Vector3d gyr = Eigen::Vector3d::Zero();
  Eigen::Vector3d acc = Eigen::Vector3d::Zero();
  double t() const { return nsToSec(t_ns); }
};

/// A camera frame on disk.
struct ImageRecord {
  int64_t t_ns = 0;
  std::string path;  ///< absolute or relative to the working directory
};

/// The rigid transform with rotation q and translation p.
inline Eigen::Isometry3d isometry(const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.toRotationMatrix();
  T.translation() = p;
  return T;
}

/// A pose T_w_b at time t (seconds).
struct StampedPose {
  double t = 0.0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Isometry3d T_w_b() const { return isometry(p, q); }
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};
using Trajectory = std::vector<StampedPose, Eigen::aligned_allocator<StampedPose>>;

/// A full ground-truth state as in EuRoC's state_groundtruth_estimate0/data.csv.
struct GroundTruthState {
  int64_t t_ns = 0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Vector3d bg = Eigen::Vector3d::Zero();
  Eigen::Vector3d ba = Eigen::Vector3d::Zero();
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};
using GroundTruth = std::vector<GroundTruthState, Eigen::aligned_allocator<GroundTruthState>>;

}  // namespace alvio
