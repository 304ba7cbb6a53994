#include "alvio/sim/surface_distance.h"

#include <algorithm>
#include <limits>

namespace alvio::sim {

double pointRectangleDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& origin,
                              const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  // With orthogonal edges the closest point clamps each coordinate on its own.
  const Eigen::Vector3d d = p - origin;
  const double a = std::clamp(d.dot(u) / u.squaredNorm(), 0.0, 1.0);
  const double b = std::clamp(d.dot(v) / v.squaredNorm(), 0.0, 1.0);
  return (origin + a * u + b * v - p).norm();
}

SurfaceDistance::SurfaceDistance(const Scene& scene) {
  for (const SceneQuad& q : scene.quads()) {
    rects_.push_back(
        {q.origin, q.edge_u, q.edge_v, q.edge_u.squaredNorm(), q.edge_v.squaredNorm()});
    Eigen::AlignedBox3d box;
    for (int i = 0; i < 4; ++i) box.extend(q.corner(i));
    boxes_.push_back(box);
  }
}

double SurfaceDistance::operator()(const Eigen::Vector3d& p) const {
  double best = std::numeric_limits<double>::infinity();
  if (rects_.empty()) return best;
  auto consider = [&](std::size_t i) {
    const Rect& r = rects_[i];
    const double d = pointRectangleDistance(p, r.origin, r.u, r.v);
    if (d < best) {
      best = d;
      last_best_ = i;
    }
  };
  consider(std::min(last_best_, rects_.size() - 1));
  for (std::size_t i = 0; i < rects_.size(); ++i)
    if (boxes_[i].exteriorDistance(p) < best) consider(i);
  return best;
}

}  // namespace alvio::sim
