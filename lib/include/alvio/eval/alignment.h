#pragma once
// Aligning an estimated trajectory to ground truth before measuring its error:
// SE(3) and Sim(3) by Umeyama's closed form, 4-DoF position + yaw (the
// unobservable directions of VIO), or none.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace alvio {

enum class AlignmentMode { kSE3, kSim3, kPosYaw, kNone };

AlignmentMode parseAlignmentMode(const std::string& name);  ///< se3|sim3|posyaw|none
const char* alignmentModeName(AlignmentMode mode);

/// p_gt ≈ s R p_est + t.
struct Similarity3 {
  double s = 1.0;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Vector3d apply(const Eigen::Vector3d& p) const { return s * R * p + t; }
};

using Points3 = std::vector<Eigen::Vector3d, Eigen::aligned_allocator<Eigen::Vector3d>>;

/// Least-squares alignment of `est` onto `gt` (same size, paired by index).
/// Throws alvio::Error with fewer than 3 pairs (2 for posyaw) or degenerate input.
Similarity3 alignPoints(const Points3& est, const Points3& gt, AlignmentMode mode);

}  // namespace alvio
