#pragma once
// Unit viewing rays of every pixel, from CameraModel::backProject of the
// distorted pixel position, computed once per camera. The table is sampled on a
// half-pixel grid (pixel centres and corners), so that sub-pixel samples for
// anti-aliasing interpolate between rays at most half a pixel apart: the error
// of that interpolation is below 1e-4 px for the EuRoC lens.

#include <Eigen/Core>
#include <vector>

#include "alvio/camera/camera_model.h"

namespace alvio::sim {

class CameraRayTable {
 public:
  /// Builds the table with up to `threads` threads.
  explicit CameraRayTable(const CameraModel& camera, int threads = 1);

  int width() const { return width_; }
  int height() const { return height_; }

  /// The exact unit ray of pixel (u, v)'s centre, in the camera frame.
  const Eigen::Vector3f& centerRay(int u, int v) const {
    return grid_[static_cast<std::size_t>(2 * v + 1) * grid_w_ + 2 * u + 1];
  }
  /// The unit ray through the (distorted) image point (x, y), e.g. a sub-pixel sample:
  /// bilinear between the table's rays, renormalised.
  Eigen::Vector3f ray(float x, float y) const {
    const float gx = clampf(2.0f * (x + 0.5f), static_cast<float>(grid_w_ - 1) - 1e-3f);
    const float gy = clampf(2.0f * (y + 0.5f), static_cast<float>(grid_h_ - 1) - 1e-3f);
    const int i = static_cast<int>(gx), j = static_cast<int>(gy);
    const float fx = gx - i, fy = gy - j;
    const std::size_t k = static_cast<std::size_t>(j) * grid_w_ + i;
    const Eigen::Vector3f top = grid_[k] + fx * (grid_[k + 1] - grid_[k]);
    const Eigen::Vector3f bottom =
        grid_[k + grid_w_] + fx * (grid_[k + grid_w_ + 1] - grid_[k + grid_w_]);
    return (top + fy * (bottom - top)).normalized();
  }
  /// Angular size of pixel (u, v) (radians; the geometric mean of its two sides).
  float pixelAngle(int u, int v) const { return angle_[static_cast<std::size_t>(v) * width_ + u]; }

 private:
  static float clampf(float v, float hi) { return v < 0.0f ? 0.0f : (v > hi ? hi : v); }
  int width_, height_;
  int grid_w_, grid_h_;
  std::vector<Eigen::Vector3f> grid_;  ///< (2W+1) x (2H+1), at x = -0.5 + i/2, y = -0.5 + j/2
  std::vector<float> angle_;
};

}  // namespace alvio::sim
