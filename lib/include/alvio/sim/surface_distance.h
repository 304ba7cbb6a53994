#pragma once
// Distance from a point to the nearest surface of a scene (any quad, one- or two-sided),
// for judging reconstructed geometry such as occupied map voxels. Exact point-rectangle
// distances; the quads' bounding boxes skip those that cannot beat the best so far.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "alvio/sim/scene.h"

namespace alvio::sim {

class SurfaceDistance {
 public:
  explicit SurfaceDistance(const Scene& scene);
  /// Distance (m) from `p` to the closest point of any quad; infinity without quads. Not
  /// thread-safe: it remembers the last nearest quad (neighbouring queries share it).
  double operator()(const Eigen::Vector3d& p) const;

 private:
  struct Rect {
    Eigen::Vector3d origin, u, v;  // v orthogonal to u
    double u2, v2;                 // squared lengths
  };
  std::vector<Rect> rects_;
  std::vector<Eigen::AlignedBox3d> boxes_;
  mutable std::size_t last_best_ = 0;  // spatial coherence: try the last winner first
};

/// Distance from `p` to the rectangle origin + a u + b v, a, b in [0, 1] (u orthogonal to v).
double pointRectangleDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& origin,
                              const Eigen::Vector3d& u, const Eigen::Vector3d& v);

}  // namespace alvio::sim
