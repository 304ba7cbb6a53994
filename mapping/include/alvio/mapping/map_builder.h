#pragma once
// MapBuilder: the mapping module's one entry point. It takes keyframe landmarks
// and trajectory poses, keeps the line map, the occupancy tree and the point
// landmarks, and writes the map files (see map_files.h). Used by the offline
// runner (alvio_run) and the mapping nodelet; no ROS.

#include <map>
#include <string>

#include "alvio/common/types.h"
#include "alvio/mapping/keyframe_landmarks.h"
#include "alvio/mapping/line_map.h"
#include "alvio/mapping/occupancy_map.h"

namespace alvio {

class YamlReader;

/// The `mapping:` section of the configuration.
struct MappingOptions {
  bool enabled = true;      ///< the offline runner builds and writes the map
  bool write_scene = true;  ///< write map.3Dscene (MRPT) besides the other files
  /// Lines whose direction is less certain than this (1 sigma, deg) stay out of the map.
  double max_line_direction_std_deg = 2.0;
  /// Points seen with less parallax than this [deg] stay out of the map (their depth is
  /// uncertain); points of unknown parallax are kept.
  double min_point_parallax_deg = 2.0;
  LineMapOptions lines;         ///< mapping.lines.*
  OccupancyMapOptions octomap;  ///< mapping.octomap.*

  /// Read `prefix` ("mapping"); absent keys keep their defaults. Throws alvio::Error
  /// naming the key; unknown keys under the prefix are logged as warnings.
  static MappingOptions load(const YamlReader& yaml, const std::string& prefix = "mapping");
};

/// Where save() put the files.
struct MapFilePaths {
  std::string octomap, lines_ply, lines_csv, scene;  ///< scene is "" when not written
};

struct MapSummary {
  std::size_t keyframes = 0, poses = 0, points = 0;
  std::size_t lines = 0;       ///< map lines before filtering
  std::size_t lines_kept = 0;  ///< lines that pass the save filter
  double lines_kept_length_m = 0;
  std::size_t line_landmarks = 0;  ///< landmark IDs remembered by the line map
  std::size_t merges = 0;
  double resolution = 0;
  VoxelCounts voxels;
  /// Bounding box of occupied voxels and kept lines; valid when has_extent.
  bool has_extent = false;
  Eigen::Vector3d extent_min = Eigen::Vector3d::Zero(), extent_max = Eigen::Vector3d::Zero();
  /// Approximate heap memory (bytes).
  std::size_t memory_lines = 0, memory_octree = 0, memory_points = 0, memory_trajectory = 0;
  std::size_t memoryTotal() const {
    return memory_lines + memory_octree + memory_points + memory_trajectory;
  }
  /// A few human-readable lines.
  std::string toString() const;
};

class MapBuilder {
 public:
  explicit MapBuilder(const MappingOptions& options = MappingOptions());

  /// Points update their landmark (latest position by ID) and go into the occupancy tree
  /// with the lines; lines go into the line map. Points with too little parallax and lines
  /// with too uncertain (or unknown) a direction are left out, whichever path (offline
  /// runner or nodelet) brings them.
  void addKeyframe(const KeyframeLandmarks& keyframe);
  /// A body pose T_w_b of the trajectory (drawn in the scene).
  void addTrajectoryPose(const StampedPose& T_w_b);

  /// Write the map files into `dir` (created if needed). Throws alvio::Error.
  MapFilePaths save(const std::string& dir) const;
  MapSummary summary() const;

  const LineMap& lineMap() const { return lines_; }
  const OccupancyMap& occupancyMap() const { return occupancy_; }
  const std::map<int, Eigen::Vector3d>& points() const { return points_; }
  const Trajectory& trajectory() const { return trajectory_; }
  const MappingOptions& options() const { return options_; }

 private:
  MappingOptions options_;
  LineMap lines_;
  OccupancyMap occupancy_;
  std::map<int, Eigen::Vector3d> points_;
  Trajectory trajectory_;
  std::size_t keyframes_ = 0;
};

}  // namespace alvio
