#pragma once
// Which true scene edge a tracked 2D line segment lies on. The truth is the visible part of
// each scene edge projected into the undistorted pinhole image (where the trackers report
// their segments) with the ground-truth camera pose. A segment lies on an edge when both its
// endpoints are within a few pixels of the edge's image line, the directions agree within a
// few degrees, and most of the segment projects onto the edge's visible part (so that a
// collinear neighbour edge further along the same image line does not match).

#include <Eigen/Core>
#include <vector>

#include "alvio/lines/line_segment.h"

namespace alvio {

/// A true edge's visible part in the pinhole image.
struct ProjectedEdge {
  int edge_id = -1;
  Eigen::Vector2d a = Eigen::Vector2d::Zero(), b = Eigen::Vector2d::Zero();
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};
using ProjectedEdges = std::vector<ProjectedEdge, Eigen::aligned_allocator<ProjectedEdge>>;

struct EdgeAssociationOptions {
  double max_endpoint_distance_px = 3.0;  ///< each endpoint to the edge's image line
  double max_angle_deg = 3.0;             ///< undirected (LSD's orientation is ignored)
  double min_overlap_ratio = 0.5;         ///< of the segment's length, onto the visible part
};

struct EdgeAssociation {
  /// The compatible edge with the smallest worst endpoint distance, -1 when none.
  int edge_id = -1;
  double endpoint_distance_px = 0;  ///< the larger of the two, for edge_id
  /// Each endpoint's distance to edge_id's image line.
  double start_distance_px = 0, end_distance_px = 0;
  double angle_deg = 0;  ///< for edge_id
  /// Every edge within the tolerances (nearly coincident edges make more than one: e.g. the
  /// front and back border of a thin panel seen edge-on).
  std::vector<int> compatible;
};

EdgeAssociation associateWithEdge(const LineSegment& segment, const ProjectedEdges& edges,
                                  const EdgeAssociationOptions& options = {});

}  // namespace alvio
