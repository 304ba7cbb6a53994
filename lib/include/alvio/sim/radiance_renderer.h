#pragma once
// Exact per-pixel ray casting of a Scene through a camera's ray table: one ray
// per pixel centre, then N x N rays in pixels that straddle a geometric edge
// (neighbours hit different quads), so edges are anti-aliased as a real pixel
// integrates them. Texture detail is filtered by mip-mapping from the ray's
// footprint. The output is linear radiance (albedo x irradiance).
//
// Speed: the image is cut into 16 x 16 pixel tiles. Each tile's rays lie in a
// pyramid (checked against every ray of the tile when the renderer is built);
// the BVH is culled once per tile against it, leaving a short list of quads
// sorted by their nearest possible distance, which each ray tests until no
// nearer hit is possible. The culling is conservative, so the result is the
// same as testing every quad.

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <vector>

#include "alvio/sim/camera_ray_table.h"
#include "alvio/sim/scene.h"
#include "alvio/sim/scene_appearance.h"

namespace alvio::sim {

struct RenderOptions {
  int threads = 1;
  /// Sub-samples per side in edge pixels (1 = no anti-aliasing).
  int edge_samples = 3;
  /// A pixel is an edge pixel when a neighbour hits another quad and their values
  /// differ by more than this fraction (edges nobody can see need no sub-samples).
  float edge_contrast = 0.02f;
};

class RadianceRenderer {
 public:
  /// Keeps references: the scene, appearance and ray table must outlive the renderer.
  RadianceRenderer(const Scene& scene, const SceneAppearance& appearance,
                   const CameraRayTable& rays);

  /// Radiance seen by a camera at pose T_w_c; `quad_ids` (optional) receives the quad
  /// hit at each pixel centre (-1 for none).
  cv::Mat1f render(const Eigen::Isometry3d& T_w_c, const RenderOptions& options,
                   cv::Mat1i* quad_ids = nullptr) const;

 private:
  static constexpr int kTile = 24;
  struct Tile {
    int u0, v0, u1, v1;
    Eigen::Vector3f normal_c[4];  ///< inward normals of the tile's pyramid, camera frame
    Eigen::Vector3f corner_c[4];  ///< the pyramid's corner rays (unit), camera frame
    float slack;                  ///< angular slack (rad) so that every ray is inside
  };
  /// A quad that rays of a tile may hit, with what the ray test needs that depends
  /// only on the camera centre o precomputed: a ray o + t d hits the quad's plane at
  /// t = num / (n.d), at fractions a = a0 + t (u.d), b = b0 + t (v.d) along its edges.
  struct Candidate {
    float min_distance;  ///< no point of the quad is nearer to the camera
    int quad;
    Eigen::Vector3f n, u_scaled, v_scaled;
    float num, a0, b0;
  };
  struct Hit {
    int quad;  ///< -1: nothing hit
    float t, a, b;
  };
  void cullTile(const Tile& tile, const Eigen::Matrix3f& R, const Eigen::Vector3f& origin,
                std::vector<Candidate>* out) const;
  Hit intersect(const std::vector<Candidate>& candidates, const Eigen::Vector3f& dir) const;
  float shade(int quad, const Eigen::Vector3f& dir, float t, float a, float b,
              float pixel_angle) const;

  const Scene& scene_;
  const SceneAppearance& appearance_;
  const CameraRayTable& rays_;
  std::vector<Tile> tiles_;
  int tiles_x_ = 0, tiles_y_ = 0;
};

}  // namespace alvio::sim
