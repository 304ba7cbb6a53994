#pragma once
// Map quality against a known scene (simulator benchmarks, synthetic tests).

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "alvio/mapping/segment_geometry.h"

namespace octomap {
class OcTree;
}

namespace alvio {

struct LineMapEvaluation {
  /// Length of map lines within the tolerances of a true edge / total map line length.
  double precision = 0;
  /// Length of true edges covered by a map line within the tolerances / total edge length.
  double recall = 0;
  double map_length_m = 0, matched_map_length_m = 0;
  double true_length_m = 0, covered_true_length_m = 0;
  std::size_t map_lines = 0, true_edges = 0;
};

/// A piece of a map line counts as correct where it lies within `dist_tol_m` of a true edge
/// whose direction is within `angle_tol_rad` of the line's; a piece of a true edge counts as
/// covered where such a map line passes within the tolerances. Both are measured by
/// sampling the segments every `dist_tol_m / 2` (at least 1 mm), weighted by length.
LineMapEvaluation evaluateLineMap(const std::vector<Segment3>& map_lines,
                                  const std::vector<Segment3>& true_edges, double dist_tol_m,
                                  double angle_tol_rad);

struct OccupancyEvaluation {
  std::size_t occupied_voxels = 0;  ///< at the finest resolution
  std::size_t within_tolerance = 0;
  double fraction = 0;  ///< within_tolerance / occupied_voxels (0 when empty)
  double mean_distance_m = 0;
};

/// Distance from a world point to the nearest true surface (m).
using SurfaceDistanceFn = std::function<double(const Eigen::Vector3d&)>;

/// Fraction of occupied voxels (finest resolution) whose centre lies within `tolerance_m`
/// of a true surface; the criterion uses 2 voxels (2 x resolution).
OccupancyEvaluation evaluateOccupancy(const octomap::OcTree& tree,
                                      const SurfaceDistanceFn& surface_distance,
                                      double tolerance_m);

}  // namespace alvio
