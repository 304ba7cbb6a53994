#pragma once
// A pose of a trajectory at any time between two of its samples: linear in position,
// slerp in rotation. Ground truth comes at the IMU rate; evaluations need it at image times.

#include <optional>

#include "alvio/common/types.h"

namespace alvio {

/// The pose at time `t` interpolated between the samples around it (sorted by time), or
/// nullopt when `t` lies outside the trajectory or the samples around it are more than
/// `max_gap_s` apart (a hole in the ground truth must not be bridged silently).
std::optional<StampedPose> interpolatePose(const Trajectory& trajectory, double t,
                                           double max_gap_s = 0.05);

}  // namespace alvio
