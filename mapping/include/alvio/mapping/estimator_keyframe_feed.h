#pragma once
// Turns the estimator's sliding window into KeyframeLandmarks for the map.
//
// Whenever the window has slid past a keyframe (its oldest keyframe changed), poll()
// returns the landmarks anchored in the new oldest keyframe, with that keyframe's camera
// pose: they are the most mature estimates of the window (optimised over the whole window,
// next to be marginalised) and that camera saw them, so its rays to them carve true free
// space. A landmark that is re-anchored when its keyframe leaves is reported again from
// the next keyframe; the map keeps its latest position. flush() reports what is still in
// the window at the end of a run.
//
// Lines do not come through here: they enter the map when they retire from the window,
// refined over their whole track (PipelineOutput::retired_lines, see MapObserver).

#include <optional>
#include <vector>

#include "alvio/estimator/estimator.h"
#include "alvio/mapping/keyframe_landmarks.h"

namespace alvio {

class EstimatorKeyframeFeed {
 public:
  /// `T_b_c`: the camera pose in the body frame (CameraOptions::T_b_c).
  explicit EstimatorKeyframeFeed(const Eigen::Isometry3d& T_b_c) : T_b_c_(T_b_c) {}

  /// Call after every frame. Returns the oldest keyframe's landmarks when the window has
  /// moved on by a keyframe since the last call, and nothing otherwise (or when the
  /// estimator is not tracking).
  std::optional<KeyframeLandmarks> poll(const Estimator& estimator);
  /// The landmarks of every keyframe still in the window, oldest first (end of a run).
  std::vector<KeyframeLandmarks> flush(const Estimator& estimator) const;

 private:
  /// Landmarks anchored in window keyframe `index`.
  KeyframeLandmarks keyframe(const Estimator& estimator, int index) const;

  Eigen::Isometry3d T_b_c_;
  double last_oldest_t_ = -1;
};

/// Lines retiring from the window (Estimator::takeRetiredLines) as the map's input, seen
/// from the camera of body state `state`, each with its direction uncertainty.
KeyframeLandmarks retiredLinesKeyframe(const BodyState& state, const Eigen::Isometry3d& T_b_c,
                                       const LineSegments3& retired);

}  // namespace alvio
