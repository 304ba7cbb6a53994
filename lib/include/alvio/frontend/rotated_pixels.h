#pragma once
// Where a pure rotation of the camera moves image points: each point's bearing rotated and
// projected again. The point and line trackers start KLT there (the gyroscope's rotation since
// the last frame), each through its own camera: the raw image's model for corners, the
// undistorted pinhole image for line samples.

#include <Eigen/Core>
#include <opencv2/core/types.hpp>
#include <vector>

namespace alvio {

/// `bearing(Eigen::Vector2d pixel)` gives a pixel's ray; `project(Eigen::Vector3d ray,
/// Eigen::Vector2d* pixel)` its pixel, false when the ray is behind the camera. A point turned
/// behind the camera keeps its position: KLT will lose it either way.
template <typename Bearing, typename Project>
std::vector<cv::Point2f> rotatedPixels(const Eigen::Matrix3d& R, const std::vector<cv::Point2f>& px,
                                       Bearing bearing, Project project) {
  std::vector<cv::Point2f> moved(px.size());
  for (std::size_t i = 0; i < px.size(); ++i) {
    Eigen::Vector2d out;
    if (project(Eigen::Vector3d(R * bearing(Eigen::Vector2d(px[i].x, px[i].y))), &out))
      moved[i] = cv::Point2f(static_cast<float>(out.x()), static_cast<float>(out.y()));
    else
      moved[i] = px[i];
  }
  return moved;
}

}  // namespace alvio
