#include "alvio/sim/camera_ray_table.h"

#include <algorithm>
#include <cmath>
#include <thread>

namespace alvio::sim {

CameraRayTable::CameraRayTable(const CameraModel& camera, int threads)
    : width_(camera.width()),
      height_(camera.height()),
      grid_w_(2 * camera.width() + 1),
      grid_h_(2 * camera.height() + 1) {
  grid_.resize(static_cast<std::size_t>(grid_w_) * grid_h_);
  auto work = [&](int first_row, int step) {
    for (int j = first_row; j < grid_h_; j += step)
      for (int i = 0; i < grid_w_; ++i) {
        const Eigen::Vector2d px(-0.5 + 0.5 * i, -0.5 + 0.5 * j);
        grid_[static_cast<std::size_t>(j) * grid_w_ + i] =
            camera.backProject(px).normalized().cast<float>();
      }
  };
  threads = std::max(1, threads);
  std::vector<std::thread> pool;
  for (int k = 1; k < threads; ++k) pool.emplace_back(work, k, threads);
  work(0, threads);
  for (auto& t : pool) t.join();

  angle_.resize(static_cast<std::size_t>(width_) * height_);
  auto at = [&](int i, int j) -> const Eigen::Vector3f& {
    return grid_[static_cast<std::size_t>(j) * grid_w_ + i];
  };
  for (int v = 0; v < height_; ++v)
    for (int u = 0; u < width_; ++u) {
      const int i = 2 * u + 1, j = 2 * v + 1;
      const float ax = std::acos(std::clamp(at(i - 1, j).dot(at(i + 1, j)), -1.0f, 1.0f));
      const float ay = std::acos(std::clamp(at(i, j - 1).dot(at(i, j + 1)), -1.0f, 1.0f));
      angle_[static_cast<std::size_t>(v) * width_ + u] = std::sqrt(ax * ay);
    }
}

}  // namespace alvio::sim
