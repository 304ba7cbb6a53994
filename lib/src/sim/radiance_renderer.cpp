#include "alvio/sim/radiance_renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>
#include <vector>

#include "alvio/common/error.h"
#include "alvio/sim/parallel_for.h"

namespace alvio::sim {

RadianceRenderer::RadianceRenderer(const Scene& scene, const SceneAppearance& appearance,
                                   const CameraRayTable& rays)
    : scene_(scene), appearance_(appearance), rays_(rays) {
  if (!scene.finalized()) throw Error("RadianceRenderer: the scene is not finalized");
  const int w = rays.width(), h = rays.height();
  tiles_x_ = (w + kTile - 1) / kTile;
  tiles_y_ = (h + kTile - 1) / kTile;
  for (int ty = 0; ty < tiles_y_; ++ty)
    for (int tx = 0; tx < tiles_x_; ++tx) {
      Tile t;
      t.u0 = tx * kTile;
      t.v0 = ty * kTile;
      t.u1 = std::min(w, t.u0 + kTile);
      t.v1 = std::min(h, t.v0 + kTile);
      // Corner rays at the tile's outer pixel borders, clockwise in the image.
      const float x0 = t.u0 - 0.5f, x1 = t.u1 - 0.5f, y0 = t.v0 - 0.5f, y1 = t.v1 - 0.5f;
      const Eigen::Vector3f c[4] = {rays.ray(x0, y0), rays.ray(x1, y0), rays.ray(x1, y1),
                                    rays.ray(x0, y1)};
      const Eigen::Vector3f centre = (c[0] + c[1] + c[2] + c[3]).normalized();
      for (int k = 0; k < 4; ++k) t.corner_c[k] = c[k];
      for (int k = 0; k < 4; ++k) {
        Eigen::Vector3f n = c[k].cross(c[(k + 1) % 4]).normalized();
        if (n.dot(centre) < 0) n = -n;
        t.normal_c[k] = n;
      }
      // Lens distortion bends the tile borders slightly: measure how far any ray of
      // the tile (pixel centres, corners, and the midpoints between) falls outside.
      float worst = 0;
      for (int j = 2 * t.v0; j <= 2 * t.v1; ++j)
        for (int i = 2 * t.u0; i <= 2 * t.u1; ++i) {
          const Eigen::Vector3f r = rays.ray(-0.5f + 0.5f * i, -0.5f + 0.5f * j);
          for (int k = 0; k < 4; ++k) worst = std::max(worst, -t.normal_c[k].dot(r));
        }
      t.slack = worst + 1e-4f;
      tiles_.push_back(t);
    }
}

void RadianceRenderer::cullTile(const Tile& tile, const Eigen::Matrix3f& R,
                                const Eigen::Vector3f& o, std::vector<Candidate>* out) const {
  Eigen::Vector3f n[4], corner_ray[4];
  for (int k = 0; k < 4; ++k) {
    n[k] = R * tile.normal_c[k];
    corner_ray[k] = R * tile.corner_c[k];
  }
  const float slack = tile.slack;
  // A box is outside if, for some plane, even its most inward corner is outside by
  // more than the slack allows at its distance.
  auto accept = [&](const float* lo, const float* hi) {
    const Eigen::Vector3f blo(lo[0], lo[1], lo[2]), bhi(hi[0], hi[1], hi[2]);
    const float reach = ((0.5f * (blo + bhi) - o).norm() + 0.5f * (bhi - blo).norm()) * slack;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3f p(n[k].x() > 0 ? bhi.x() : blo.x(), n[k].y() > 0 ? bhi.y() : blo.y(),
                              n[k].z() > 0 ? bhi.z() : blo.z());
      if (n[k].dot(p - o) < -reach) return false;
    }
    return true;
  };
  const auto& quads = scene_.fastQuads();
  out->clear();
  scene_.bvh().traverseIf(accept, [&](int qi) {
    const Scene::FastQuad& q = quads[qi];
    const float side = q.normal.dot(o - q.origin);
    if (!q.two_sided && side <= 0) return;  // its back faces the camera: never hit
    const Eigen::Vector3f eu = q.u_scaled * (q.length_u * q.length_u);
    const Eigen::Vector3f ev = q.v_scaled * (q.length_v * q.length_v);
    const Eigen::Vector3f corner[4] = {q.origin, q.origin + eu, q.origin + eu + ev, q.origin + ev};
    for (int k = 0; k < 4; ++k) {
      bool all_out = true;
      for (const auto& c : corner)
        if (n[k].dot(c - o) >= -slack * (c - o).norm()) {
          all_out = false;
          break;
        }
      if (all_out) return;
    }
    // Nearest possible distance: to its bounding box, and along the tile's rays to its
    // plane. A ray d meets the plane at |side| / |n.d|, and |n.d| over the tile's rays
    // is at most its largest value at the pyramid's corners (plus the slack): planes
    // seen at a grazing angle are far along every ray of the tile.
    Eigen::Vector3f lo = corner[0], hi = corner[0];
    for (int i = 1; i < 4; ++i) {
      lo = lo.cwiseMin(corner[i]);
      hi = hi.cwiseMax(corner[i]);
    }
    const float box = (o.cwiseMax(lo).cwiseMin(hi) - o).norm();
    float max_cos = 0;
    for (const auto& r : corner_ray) max_cos = std::max(max_cos, std::abs(q.normal.dot(r)));
    const float along = std::abs(side) / std::min(1.0f, max_cos * 1.002f + 2 * slack + 1e-3f);
    const Eigen::Vector3f to_camera = o - q.origin;
    out->push_back({std::max(along, box) * 0.999f - 1e-4f, qi, q.normal, q.u_scaled, q.v_scaled,
                    -side, to_camera.dot(q.u_scaled), to_camera.dot(q.v_scaled)});
  });
  std::sort(out->begin(), out->end(), [](const Candidate& a, const Candidate& b) {
    return a.min_distance < b.min_distance || (a.min_distance == b.min_distance && a.quad < b.quad);
  });

  // Occlusion: if a quad covers the whole tile (every ray of it, slack included, hits
  // it) no farther than D, no candidate whose nearest possible distance exceeds D can
  // be seen in this tile: drop them. They would only have been tested and missed, so
  // the image does not change; walls and floors then hide what lies behind them.
  float cover = std::numeric_limits<float>::max();
  const int checks = std::min<int>(static_cast<int>(out->size()), 12);
  for (int i = 0; i < checks; ++i) {
    const Candidate& c = (*out)[i];
    if (c.min_distance >= cover) break;
    const Scene::FastQuad& q = quads[c.quad];
    const float side = q.normal.dot(o - q.origin);
    const Eigen::Vector3f n_in = side > 0 ? -q.normal : q.normal;  // along the view
    float min_cos = 1.0f;
    for (const auto& r : corner_ray) min_cos = std::min(min_cos, n_in.dot(r));
    const float margin_cos = min_cos - 2 * slack - 1e-3f;
    if (margin_cos < 0.05f) continue;  // grazing: not worth it
    const float far = std::abs(side) / margin_cos;
    const float margin = 2.0f * (slack + 1e-3f) * far / margin_cos + 1e-3f;
    bool covers = true;
    for (const auto& r : corner_ray) {
      const float t = std::abs(side) / n_in.dot(r);
      const Eigen::Vector3f d = o + t * r - q.origin;
      const float a = d.dot(q.u_scaled) * q.length_u, b = d.dot(q.v_scaled) * q.length_v;
      if (a < margin || a > q.length_u - margin || b < margin || b > q.length_v - margin) {
        covers = false;
        break;
      }
    }
    if (covers) cover = std::min(cover, far);
  }
  if (cover < std::numeric_limits<float>::max()) {
    out->erase(std::remove_if(out->begin(), out->end(),
                              [&](const Candidate& c) { return c.min_distance > cover; }),
               out->end());
  }
}

float RadianceRenderer::shade(int quad, const Eigen::Vector3f& dir, float t, float a, float b,
                              float pixel_angle) const {
  const Scene::FastQuad& q = scene_.fastQuads()[quad];
  const SceneAppearance::Mapping& m = appearance_.mapping(quad);
  const float am = a * q.length_u, bm = b * q.length_v;
  const float x = ((m.swap ? bm : am) + m.offset_x) * m.inv_texel;
  const float y = ((m.swap ? q.length_u - am : q.length_v - bm) + m.offset_y) * m.inv_texel;
  const float facing = q.normal.dot(dir);
  // Footprint of the pixel on the surface, in texels (stretched by the slant).
  const float slant = std::sqrt(std::max(std::abs(facing), 0.02f));
  const float footprint = t * pixel_angle * m.inv_texel / slant;
  const float albedo = appearance_.texture(m.texture).sample(x, y, footprint);
  if (m.emissive > 0) return m.emissive * albedo;
  const bool back = q.two_sided && facing > 0;
  return albedo * appearance_.lightMap(quad).irradiance(back, a, b);
}

RadianceRenderer::Hit RadianceRenderer::intersect(const std::vector<Candidate>& candidates,
                                                  const Eigen::Vector3f& dir) const {
  Hit hit{-1, 1e30f, 0, 0};
  for (const Candidate& c : candidates) {
    if (c.min_distance >= hit.t) break;  // nothing further down the list can be nearer
    // Back faces need no test of their own: cullTile dropped one-sided quads whose back
    // faces the camera, and rays leaving a plane get t < 0 (n.d = 0 gives inf or NaN).
    const float t = c.num / c.n.dot(dir);
    if (!(t > 1e-5f) || t >= hit.t) continue;
    const float a = c.a0 + t * c.u_scaled.dot(dir);
    if (a < 0.0f || a > 1.0f) continue;
    const float b = c.b0 + t * c.v_scaled.dot(dir);
    if (b < 0.0f || b > 1.0f) continue;
    hit = {c.quad, t, a, b};
  }
  return hit;
}

cv::Mat1f RadianceRenderer::render(const Eigen::Isometry3d& T_w_c, const RenderOptions& options,
                                   cv::Mat1i* quad_ids) const {
  const int w = rays_.width(), h = rays_.height();
  const int threads = std::max(1, options.threads);
  const Eigen::Matrix3f R = T_w_c.linear().cast<float>();
  const Eigen::Vector3f origin = T_w_c.translation().cast<float>();
  cv::Mat1f image(h, w);
  cv::Mat1i ids(h, w);
  std::vector<std::vector<Candidate>> candidates(tiles_.size());

  // Pass 1: one ray per pixel centre, tile by tile (a tile row per task).
  parallelFor(tiles_y_, threads, [&](int ty) {
    for (int tx = 0; tx < tiles_x_; ++tx) {
      const int ti = ty * tiles_x_ + tx;
      const Tile& tile = tiles_[ti];
      cullTile(tile, R, origin, &candidates[ti]);
      for (int v = tile.v0; v < tile.v1; ++v) {
        float* out = image.ptr<float>(v);
        int* id = ids.ptr<int>(v);
        for (int u = tile.u0; u < tile.u1; ++u) {
          const Eigen::Vector3f dir = R * rays_.centerRay(u, v);
          const Hit hit = intersect(candidates[ti], dir);
          out[u] = hit.quad < 0 ? 0.0f
                                : shade(hit.quad, dir, hit.t, hit.a, hit.b, rays_.pixelAngle(u, v));
          id[u] = hit.quad;
        }
      }
    }
  });

  // Pass 2: pixels on a visible geometric edge get n x n sub-pixel rays, which find
  // how much of the pixel each quad covers. Each quad is shaded once (textures are
  // already filtered over the pixel's footprint); the pixel is the coverage-weighted
  // mean.
  const int n = std::max(1, options.edge_samples);
  if (n > 1) {
    cv::Mat1f refined = image.clone();
    const float contrast = options.edge_contrast;
    parallelFor(tiles_y_, threads, [&](int ty) {
      for (int tx = 0; tx < tiles_x_; ++tx) {
        const int ti = ty * tiles_x_ + tx;
        const Tile& tile = tiles_[ti];
        for (int v = tile.v0; v < tile.v1; ++v) {
          const int* row = ids.ptr<int>(v);
          const float* val = image.ptr<float>(v);
          const int vu = std::max(v - 1, 0), vd = std::min(v + 1, h - 1);
          float* out = refined.ptr<float>(v);
          for (int u = tile.u0; u < tile.u1; ++u) {
            const int c = row[u];
            const float x0 = val[u];
            auto differs = [&](int uu, int vv) {
              if (ids(vv, uu) == c) return false;
              const float x1 = image(vv, uu);
              return std::abs(x1 - x0) > contrast * std::max(x0, x1) + 1e-4f;
            };
            if (!differs(std::max(u - 1, 0), v) && !differs(std::min(u + 1, w - 1), v) &&
                !differs(u, vu) && !differs(u, vd))
              continue;
            const float angle = rays_.pixelAngle(u, v);
            constexpr int kMaxQuads = 6;
            int quad[kMaxQuads], count[kMaxQuads];
            float value[kMaxQuads];
            int distinct = 1;
            quad[0] = c;
            count[0] = 0;
            value[0] = x0;
            for (int j = 0; j < n; ++j)
              for (int i = 0; i < n; ++i) {
                const float x = u - 0.5f + (i + 0.5f) / n, y = v - 0.5f + (j + 0.5f) / n;
                const Eigen::Vector3f dir = R * rays_.ray(x, y);
                const Hit hit = intersect(candidates[ti], dir);
                int k = 0;
                while (k < distinct && quad[k] != hit.quad) ++k;
                if (k == distinct && distinct == kMaxQuads) {
                  k = 0;  // more quads than that in one pixel: count them as the centre's
                } else if (k == distinct) {
                  quad[k] = hit.quad;
                  count[k] = 0;
                  value[k] = hit.quad < 0 ? 0.0f : shade(hit.quad, dir, hit.t, hit.a, hit.b, angle);
                  ++distinct;
                }
                ++count[k];
              }
            float sum = 0;
            for (int k = 0; k < distinct; ++k) sum += count[k] * value[k];
            out[u] = sum / (n * n);
          }
        }
      }
    });
    image = refined;
  }
  if (quad_ids) *quad_ids = ids;
  return image;
}

}  // namespace alvio::sim
