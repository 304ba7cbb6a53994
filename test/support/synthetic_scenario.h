#pragma once
// A feature-level synthetic scenario for estimator tests that need no
// rendering: a smooth analytic trajectory, its exact IMU (plus optional noise),
// and point observations of landmarks on the walls of a room, with stable IDs.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <map>
#include <random>
#include <set>
#include <vector>

#include "alvio/common/types.h"
#include "alvio/config/sensor_options.h"
#include "alvio/frontend/feature_frame.h"

namespace alvio::test {

struct ScenarioOptions {
  double duration_s = 20;
  double camera_rate_hz = 20;
  double imu_rate_hz = 200;
  double pixel_noise = 0.5;  ///< sigma, pixels
  bool imu_noise = true;
  int max_points = 150;
  int max_lines = 40;       ///< line observations per frame (0: none)
  double line_noise = 0.5;  ///< endpoint noise across the line, pixels
  unsigned seed = 1;
};

class SyntheticScenario {
 public:
  SyntheticScenario(const ScenarioOptions& options, const CameraOptions& camera,
                    const ImuOptions& imu);

  /// True body pose at time t (t from 0).
  Eigen::Vector3d position(double t) const;
  Eigen::Matrix3d rotation(double t) const;
  Eigen::Vector3d velocity(double t) const;

  const std::vector<ImuSample>& imu() const { return imu_; }
  const std::vector<FeatureFrame>& frames() const { return frames_; }
  /// The true 3D segments the line observations come from.
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& lineSegments() const {
    return segments_;
  }
  Trajectory groundTruth() const;
  static constexpr int64_t kStartNs = 1000000000000LL;  // t = 0 maps to 1000 s

 private:
  void makeImu(const ImuOptions& imu);
  void makeFrames(const CameraOptions& camera);
  void addLines(const Eigen::Isometry3d& T_c_w, const CameraOptions& camera, FeatureFrame* frame);

  ScenarioOptions options_;
  std::mt19937 rng_;
  std::vector<Eigen::Vector3d> landmarks_;
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> segments_;
  std::vector<ImuSample> imu_;
  std::vector<FeatureFrame> frames_;
  std::set<int> tracked_lines_;
  std::map<int, int> line_track_id_;
  int next_line_id_ = 0;
};

}  // namespace alvio::test
