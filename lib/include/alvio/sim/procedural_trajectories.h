#pragma once
// Built-in trajectories for scenes without a ground-truth file. Like the real
// EuRoC sequences they start with the sensor standing still, then accelerate
// smoothly, so that VIO initialisation sees a rest phase and then excitation.
// The body tilts with its horizontal acceleration as a multicopter does.

#include <string>
#include <vector>

#include "alvio/common/types.h"

namespace alvio::sim {

struct FigureEightOptions {
  Eigen::Vector3d center{6.0, 3.0, 0.8};
  double half_length_m = 4.0;  ///< along x
  double half_width_m = 2.0;   ///< along y
  double height_amplitude_m = 0.4;
  double lap_period_s = 16.0;
};

struct CorridorWalkOptions {
  Eigen::Vector3d start{0.0, 0.0, 1.5};
  double length_m = 12.0;  ///< walked along +x, then back
  double speed_mps = 1.1;
  double look_around_deg = 35.0;  ///< yaw sway amplitude
};

struct ProceduralPathOptions {
  double duration_s = 30.0;
  double still_s = 3.0;  ///< standing still at the start
  double ramp_s = 3.0;   ///< smooth speed-up after the still phase
  double rate_hz = 200.0;
  double start_time_s = 0.0;
  /// Camera pose in the body frame, so that the camera (not the IMU) looks where intended.
  Eigen::Isometry3d T_b_c = Eigen::Isometry3d::Identity();
  FigureEightOptions figure_eight;
  CorridorWalkOptions corridor;
};

/// Names accepted by makeProceduralTrajectory: "figure8", "corridor".
std::vector<std::string> proceduralTrajectoryNames();
bool isProceduralTrajectoryName(const std::string& name);

/// Dense body poses T_w_b of the named path; throws alvio::Error on an unknown name.
Trajectory makeProceduralTrajectory(const std::string& name, const ProceduralPathOptions& options);

}  // namespace alvio::sim
