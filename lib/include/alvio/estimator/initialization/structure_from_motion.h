#pragma once
// Up-to-scale visual structure from motion over the frames of the window, the
// first step of initialisation: relative pose from the essential matrix, then
// triangulation, PnP for the other frames, and a bundle adjustment.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <map>
#include <vector>

namespace alvio {

/// Relative pose of camera b in camera a from normalised correspondences (x_a, x_b), by
/// RANSAC on the essential matrix. Returns false with too few inliers.
bool relativePoseFromEssential(const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& corr,
                               Eigen::Matrix3d* R_a_b, Eigen::Vector3d* t_a_b);

struct SfmTrack {
  int id = -1;
  std::vector<std::pair<int, Eigen::Vector2d>> sightings;  ///< (frame index, normalised xy)
};

struct SfmResult {
  /// Camera poses T_ref_c (camera to the reference camera frame), one per frame.
  std::vector<Eigen::Quaterniond, Eigen::aligned_allocator<Eigen::Quaterniond>> q_ref_c;
  std::vector<Eigen::Vector3d, Eigen::aligned_allocator<Eigen::Vector3d>> t_ref_c;
  /// Triangulated landmarks in the reference frame, by track id.
  std::map<int, Eigen::Vector3d> points;
};

/// Reconstruct `num_frames` cameras with frame `ref` as the origin and the pose of the last
/// frame in it given (its translation fixes the scale). False if PnP or BA fails.
bool reconstructStructure(int num_frames, int ref, const Eigen::Matrix3d& R_ref_last,
                          const Eigen::Vector3d& t_ref_last, const std::vector<SfmTrack>& tracks,
                          SfmResult* result);

/// Pose of a camera from 3D points (reference frame) and their normalised observations,
/// refined from an initial guess. False with fewer than 6 points or on failure.
bool cameraPoseFromPoints(const std::vector<Eigen::Vector3d>& points,
                          const std::vector<Eigen::Vector2d>& observations,
                          Eigen::Matrix3d* R_ref_c, Eigen::Vector3d* t_ref_c);

}  // namespace alvio
