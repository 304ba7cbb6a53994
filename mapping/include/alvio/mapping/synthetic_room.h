#pragma once
// A synthetic input for the mapping module: a camera circling inside a box room
// with window frames on its walls, observing the room's straight edges and points
// on its walls with noise, lap after lap. Line tracks break after a few keyframes
// and whenever an edge leaves the view, so the same walls come back under new
// landmark IDs (what merging must absorb); a few one-off spurious segments stand
// for outliers. Used by the mapping tests and the alvio_map_bench tool until the
// full simulator drives the mapping benchmark.

#include <Eigen/Core>
#include <vector>

#include "alvio/common/types.h"
#include "alvio/mapping/keyframe_landmarks.h"
#include "alvio/mapping/segment_geometry.h"

namespace alvio {

struct SyntheticRoomOptions {
  Eigen::Vector3d size = Eigen::Vector3d(8, 6, 3);  ///< room from (0,0,0) to size (m)
  int laps = 4;
  int keyframes_per_lap = 60;
  int keyframes_per_track = 6;  ///< a line landmark ID lives at most this many keyframes
  int frames_per_keyframe = 3;  ///< image observations added per keyframe to a track
  /// Std of each coordinate of a track's line estimate at the edge ends (fixed per track);
  /// each report adds a jitter of a third of it.
  double endpoint_noise_m = 0.01;
  double point_noise_m = 0.01;  ///< std of each point coordinate
  int points_per_keyframe = 40;
  double outliers_per_keyframe = 0.5;  ///< mean number of spurious one-off segments
  double view_range_m = 7;
  double fov_deg = 90;  ///< full horizontal and vertical field of view
  unsigned seed = 1;
};

struct SyntheticRoom {
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  std::vector<Segment3> edges;  ///< the true straight edges of the room
  std::vector<KeyframeLandmarks> keyframes;
  Trajectory trajectory;  ///< camera poses (body = camera)
  /// Distance from `p` to the nearest wall, floor or ceiling (m).
  double surfaceDistance(const Eigen::Vector3d& p) const;
};

SyntheticRoom makeSyntheticRoom(const SyntheticRoomOptions& options);

}  // namespace alvio
