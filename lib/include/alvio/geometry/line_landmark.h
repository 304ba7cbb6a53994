#pragma once
// Bookkeeping of one 3D line landmark. The estimator owns the window logic (when to
// triangulate, which observations to drop, outlier rejection); this struct only holds the
// state and keeps the observed extent consistent with the line.

#include <Eigen/Core>
#include <cstdint>
#include <map>

#include "alvio/geometry/plucker_line.h"

namespace alvio {

enum class LineLandmarkStatus {
  kNew,           ///< observed, not yet triangulated
  kTriangulated,  ///< has an initial 3D line
  kOptimised,     ///< refined over its whole track, when it left the window
  kOutlier,       ///< rejected (large residuals); kept only so its ID is not reused
};
const char* toString(LineLandmarkStatus status);

/// A segment observation of the landmark in one frame (undistorted normalised endpoints).
struct LineLandmarkObservation {
  Eigen::Vector2d start_norm = Eigen::Vector2d::Zero();
  Eigen::Vector2d end_norm = Eigen::Vector2d::Zero();
  bool edge_checked = false;  ///< LineObservation::edge_checked
  bool on_edge = false;       ///< the map's positions below are set (LineObservation::on_edge)
  Eigen::Vector2d edge_start_norm = Eigen::Vector2d::Zero();
  Eigen::Vector2d edge_end_norm = Eigen::Vector2d::Zero();
  /// The endpoints' image velocities across the line (normalised units per second), from the
  /// line's previous observation; zero for its first. Only the time shift's estimate uses them.
  Eigen::Vector2d start_velocity = Eigen::Vector2d::Zero();
  Eigen::Vector2d end_velocity = Eigen::Vector2d::Zero();
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

struct LineLandmark {
  int id = -1;  ///< the front end's track ID
  LineLandmarkStatus status = LineLandmarkStatus::kNew;
  /// Observations keyed by the estimator's frame key (e.g. timestamp in ns), in time order.
  std::map<int64_t, LineLandmarkObservation, std::less<int64_t>,
           Eigen::aligned_allocator<std::pair<const int64_t, LineLandmarkObservation>>>
      observations;
  PluckerLine line_w;  ///< valid unless status == kNew
  /// Endpoints on line_w bounding the union of the observed segments (valid if has_extent).
  Eigen::Vector3d start_w = Eigen::Vector3d::Zero();
  Eigen::Vector3d end_w = Eigen::Vector3d::Zero();
  bool has_extent = false;
  /// 1-sigma uncertainty of the line's direction from its window observations [deg]
  /// (negative until computed). Lines seen with little parallax are poorly constrained.
  double direction_std_deg = -1;
  /// 1-sigma uncertainty of the extent's midpoint across the line [m] over the whole track
  /// (set when the line retires; negative before).
  double midpoint_std_m = -1;
  /// Observations over the whole track (set when the line retires from the window).
  int track_observations = 0;

  bool hasLine() const { return status != LineLandmarkStatus::kNew; }
  /// Set a new line (after triangulation or optimisation); the old extent is projected
  /// onto it so that it stays on the line.
  void setLine(const PluckerLine& line, LineLandmarkStatus new_status);
  /// Grow the extent to include the segment p-q (both projected onto line_w first).
  void unionExtent(const Eigen::Vector3d& p, const Eigen::Vector3d& q);

  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// Orthogonal projection of a point onto a line.
Eigen::Vector3d projectOntoLine(const PluckerLine& line, const Eigen::Vector3d& p);

}  // namespace alvio
