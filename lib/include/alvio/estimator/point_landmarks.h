#pragma once
// Point landmarks of the sliding window (VINS-Mono's feature manager): their
// observations per keyframe, inverse-depth anchoring in the first observing
// keyframe, the parallax-based keyframe decision, triangulation, and the
// bookkeeping when a keyframe leaves the window.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <functional>
#include <map>
#include <vector>

#include "alvio/frontend/feature_frame.h"

namespace alvio {

struct PointSighting {
  Eigen::Vector3d xy1 = Eigen::Vector3d::UnitZ();  ///< undistorted normalised (x, y, 1)
  Eigen::Vector2d px = Eigen::Vector2d::Zero();    ///< pixel position (for analysis)
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();
};

struct PointLandmark {
  enum class State { kNew, kTriangulated, kFailed };
  int id = -1;
  int start_frame = 0;                   ///< window index of the first sighting
  std::vector<PointSighting> sightings;  ///< consecutive window frames from start_frame
  double depth = -1;                     ///< in the start frame's camera; <= 0 unknown
  State state = State::kNew;
  int endFrame() const { return start_frame + static_cast<int>(sightings.size()) - 1; }
  /// Whether the optimiser should use it: seen twice and not only in the newest frames.
  bool usable(int window_size) const {
    return sightings.size() >= 2 && start_frame < window_size - 2;
  }
};

class PointLandmarks {
 public:
  PointLandmarks(int window_size, double min_parallax_normalized)
      : window_size_(window_size), min_parallax_(min_parallax_normalized) {}

  /// Add the frame at window index `frame_index`; returns true if it should be a keyframe
  /// (enough parallax against the previous frames, or too few tracked points).
  bool addFrameAndCheckParallax(int frame_index, const FeatureFrame& frame);

  /// Normalised correspondences between window frames `a` and `b`.
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> correspondences(int a, int b) const;

  /// Triangulate every usable landmark without a depth, from all its sightings.
  /// Poses are body poses in the world; T_b_c the camera extrinsic.
  void triangulate(const std::vector<Eigen::Vector3d>& P, const std::vector<Eigen::Matrix3d>& R,
                   const Eigen::Isometry3d& T_b_c);
  /// Triangulate again, at the current poses and along each one's first sighting's ray, the
  /// usable landmarks with a depth that `which` names (those the optimiser leaves out keep a
  /// stale depth otherwise). A degenerate or negative depth keeps the last one.
  void retriangulate(const std::vector<Eigen::Vector3d>& P, const std::vector<Eigen::Matrix3d>& R,
                     const Eigen::Isometry3d& T_b_c,
                     const std::function<bool(const PointLandmark&)>& which);

  int usableCount() const;
  /// Whether any landmark was seen in window frame `frame_index`.
  bool seenIn(int frame_index) const;
  /// Inverse depths of usable landmarks in iteration order, and their write-back.
  Eigen::VectorXd inverseDepths() const;
  void setInverseDepths(const Eigen::VectorXd& inv_depths);
  void clearDepths();

  /// The oldest keyframe leaves: re-anchor landmarks started there in the next frame
  /// (poses are camera poses of the old and the new first frame), or drop them.
  void removeOldestShiftDepth(const Eigen::Matrix3d& R_old, const Eigen::Vector3d& p_old,
                              const Eigen::Matrix3d& R_new, const Eigen::Vector3d& p_new);
  /// The oldest keyframe leaves before initialisation (no depths yet).
  void removeOldest();
  /// The second-newest frame (index frame_index - 1) is dropped.
  void removeSecondNewest(int frame_index);
  /// Drop landmarks whose depth went negative, and the given IDs (reprojection outliers).
  void removeFailures();
  void removeIds(const std::vector<int>& ids);
  void clear() { landmarks_.clear(); }

  int lastTrackedCount() const { return last_track_num_; }
  std::map<int, PointLandmark>& landmarks() { return landmarks_; }
  const std::map<int, PointLandmark>& landmarks() const { return landmarks_; }

 private:
  int window_size_;
  double min_parallax_;
  int last_track_num_ = 0;
  std::map<int, PointLandmark> landmarks_;  // by id: deterministic order
};

}  // namespace alvio
