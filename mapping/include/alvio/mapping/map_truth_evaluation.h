#pragma once
// A map from a run against the true scene: the map lines and the occupied voxels, brought
// into the true world by the trajectory alignment (estimate -> ground truth), are compared with
// the scene's true edges and surfaces.
//
// - Line errors: each map line's nearest true edge is the one with the smallest mean distance
//   of the line's endpoints and midpoint to the edge segment (the midpoint alone would pick a
//   perpendicular edge near a corner); reported are the angle to that edge and the distance of
//   the line's midpoint to the edge's infinite line.
// - Precision / recall of the line map within distance and angle tolerances (map_evaluation.h).
// - Occupancy: fraction of occupied voxels within a tolerance of a true surface.

#include <Eigen/Core>
#include <vector>

#include "alvio/eval/alignment.h"
#include "alvio/mapping/map_evaluation.h"
#include "alvio/mapping/segment_geometry.h"

namespace alvio {

struct LineErrorSummary {
  std::size_t lines = 0;
  double median_angle_deg = 0, p90_angle_deg = 0;
  double median_midpoint_distance_m = 0, p90_midpoint_distance_m = 0;
};

struct LineError {
  int edge = -1;  ///< index into the true edges, -1 when there are none
  double angle_deg = 0, midpoint_distance_m = 0;
};

/// The error of one line against its nearest true edge (see above).
LineError lineErrorToNearestEdge(const Segment3& line, const std::vector<Segment3>& true_edges);
/// How far a line strays from the true surfaces: the largest distance of its endpoints and
/// midpoint to one. A line "lies on a surface" when this is within the line tolerance.
double lineSurfaceDistance(const Segment3& line, const SurfaceDistanceFn& surface_distance);
/// Medians and 90th percentiles over `lines`.
LineErrorSummary summariseLineErrors(const std::vector<Segment3>& lines,
                                     const std::vector<Segment3>& true_edges);

struct MapTruthOptions {
  double line_distance_tol_m = 0.10;
  double line_angle_tol_deg = 3.0;
  double voxel_tolerance_m = 0.10;  ///< 2 voxels at 0.05 m
};

struct MapTruthEvaluation {
  LineErrorSummary line_errors;
  /// Length fraction of map lines lying on a true surface (both endpoints and the midpoint
  /// within the line distance tolerance of one): texture lines are there, not on edges.
  double line_on_surface_fraction = 0;
  LineMapEvaluation line_map;
  OccupancyEvaluation occupancy;
};

/// Evaluate map lines and an occupancy tree given in the estimate's world frame; `T_gt_est`
/// maps that frame into the true world. `tree` may be null (no occupancy figures).
MapTruthEvaluation evaluateMapAgainstTruth(const std::vector<Segment3>& lines_est,
                                           const octomap::OcTree* tree, const Similarity3& T_gt_est,
                                           const std::vector<Segment3>& true_edges,
                                           const SurfaceDistanceFn& surface_distance,
                                           const MapTruthOptions& options = {});

}  // namespace alvio
