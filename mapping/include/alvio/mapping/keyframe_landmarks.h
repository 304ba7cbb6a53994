#pragma once
// What the estimator hands to the mapping module at a keyframe: the keyframe's
// camera pose and the landmarks it anchors, all in the (output) world frame.
// Filled by the offline runner (EstimatorKeyframeFeed) and, over ROS, by the
// estimator nodelet's keyframe landmark message. Plain data, Eigen only.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace alvio {

/// A triangulated point landmark.
struct LandmarkPoint {
  int id = -1;
  Eigen::Vector3d p_w = Eigen::Vector3d::Zero();
  /// Largest angle at the point between the rays of two cameras that saw it [deg]; its
  /// depth error grows as this shrinks. Negative: unknown.
  double parallax_deg = -1;
};

/// A 3D line landmark as a finite segment: its two endpoints (the observed extent on the
/// optimised infinite line), its landmark ID and how many image observations support it.
/// `observations` is cumulative for the ID: a later report of the same ID carries the
/// total so far, not the increment.
struct LandmarkSegment {
  int id = -1;
  Eigen::Vector3d p0_w = Eigen::Vector3d::Zero();
  Eigen::Vector3d p1_w = Eigen::Vector3d::Zero();
  int observations = 1;
  /// 1-sigma uncertainty of the line's direction [deg], from the estimator; negative: it
  /// could not be computed. The map keeps only lines below MappingOptions'
  /// max_line_direction_std_deg (0, the default, always passes).
  double direction_std_deg = 0;
  /// 1-sigma uncertainty of the midpoint across the line [m] (retired lines); negative:
  /// unknown. Carried into the map files.
  double midpoint_std_m = -1;
};

struct KeyframeLandmarks {
  double t = 0;  ///< keyframe time (s)
  /// Camera pose of the keyframe, T_w_c: the origin of the rays that carve free space.
  Eigen::Isometry3d T_w_c = Eigen::Isometry3d::Identity();
  std::vector<LandmarkPoint> points;
  std::vector<LandmarkSegment> lines;
};

}  // namespace alvio
