#pragma once
// The camera's rotation between two images from the points both track, for the time shift's
// estimate (time_shift.h): the essential matrix's, so that the translation's parallax does not
// pass for rotation.

#include <Eigen/Core>
#include <cstdint>
#include <optional>

#include "alvio/frontend/feature_frame.h"

namespace alvio {

/// The camera's rotation between two images, seen in their tracked points.
struct FrameRotation {
  int64_t t0_ns = 0, t1_ns = 0;  ///< the two images' stamps (camera clock)
  /// Rotation vector (rad) of the second camera's orientation in the first camera's frame.
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();
  int points = 0;  ///< points it was fitted on
};

/// The rotation between two frames from the points both track (their undistorted normalised
/// positions): the essential matrix's, fitted by RANSAC with `inlier_threshold` (normalised
/// units: about a pixel over the focal length), so that the translation's parallax does not pass
/// for rotation. Nothing when fewer than `min_points` are common to both or fit, or when the
/// fit is ambiguous.
std::optional<FrameRotation> rotationBetween(const FeatureFrame& first, const FeatureFrame& second,
                                             int min_points = 20, double inlier_threshold = 0.002);

}  // namespace alvio
