#pragma once
// Reading and writing pose trajectories in the formats that VIO users meet:
// TUM ("t tx ty tz qx qy qz qw", seconds), EuRoC ground-truth CSV
// ("t_ns,px,py,pz,qw,qx,qy,qz,..."), and VINS-Mono result CSV (same columns,
// trailing comma).

#include <string>

#include "alvio/common/types.h"
#include "alvio/io/time_order.h"

namespace alvio {

enum class TrajectoryFormat { kAuto, kTum, kEuroc, kVinsMono };

/// "auto", "tum", "euroc", "vins" -> format; throws alvio::Error on anything else.
TrajectoryFormat parseTrajectoryFormat(const std::string& name);
const char* trajectoryFormatName(TrajectoryFormat format);

/// Guess the format from the first data row: commas mean EuRoC/VINS CSV
/// (ns stamps, w-first quaternions), whitespace with 8 columns means TUM.
TrajectoryFormat detectTrajectoryFormat(const std::string& path);

/// Read a trajectory; malformed rows throw alvio::Error with file and line.
/// Quaternions are normalised; a quaternion far from unit length is an error.
Trajectory readTrajectory(const std::string& path,
                          TrajectoryFormat format = TrajectoryFormat::kAuto,
                          TimeOrderPolicy policy = TimeOrderPolicy::kStrict);

/// Write TUM with 9 decimals on time (ns resolution) and 9 on values. Atomic.
void writeTumTrajectory(const std::string& path, const Trajectory& trajectory);

/// Write a file by writing "<path>.tmp" and renaming it, so readers never see half a file.
void writeFileAtomically(const std::string& path, const std::string& content);

}  // namespace alvio
