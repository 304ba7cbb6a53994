#include "alvio/sim/texture_edges.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "alvio/lines/line_segment.h"

namespace alvio::sim {
namespace {

// Mean |albedo(left) - albedo(right)| over samples along the segment (texel coordinates).
float contrastAcross(const Texture& texture, const Eigen::Vector2f& a, const Eigen::Vector2f& b,
                     float offset) {
  const Eigen::Vector2f d = b - a;
  const float len = d.norm();
  if (!(len > 0)) return 0;
  const Eigen::Vector2f n = Eigen::Vector2f(-d.y(), d.x()) / len * offset;
  const int samples = std::max(2, static_cast<int>(len / 2));
  float sum = 0;
  for (int i = 0; i < samples; ++i) {
    const Eigen::Vector2f p = a + d * ((i + 0.5f) / samples);
    sum += std::abs(texture.sample(p.x() + n.x(), p.y() + n.y(), 1.0f) -
                    texture.sample(p.x() - n.x(), p.y() - n.y(), 1.0f));
  }
  return sum / samples;
}

}  // namespace

std::vector<TexelSegment> detectTextureEdges(const Texture& texture, double texel_m,
                                             const TextureEdgeOptions& options) {
  std::vector<TexelSegment> out;
  if (texture.levels() == 0 || texture.width() < 8 || texture.height() < 8) return out;
  // Default LSD (standard refinement, scale 0.8 as in the paper's method): it reports edges,
  // the borders of regions of one gradient direction, with sub-texel endpoints.
  const cv::Ptr<cv::LineSegmentDetector> lsd = cv::createLineSegmentDetector();
  std::vector<cv::Vec4f> lines;
  lsd->detect(texture.level(0), lines);
  const double min_texels = options.min_length_m / texel_m;
  for (const cv::Vec4f& l : lines) {
    // LSD puts pixel centres at integers; Texture::sample at +0.5.
    const Eigen::Vector2f a(l[0] + 0.5f, l[1] + 0.5f), b(l[2] + 0.5f, l[3] + 0.5f);
    if ((b - a).norm() < min_texels) continue;
    const float c =
        contrastAcross(texture, a, b, static_cast<float>(options.contrast_offset_texels));
    if (c < options.min_contrast) continue;
    out.push_back({a.x(), a.y(), b.x(), b.y(), c});
  }
  return out;
}

std::vector<SceneEdge> sceneTextureEdges(const Scene& scene, const SceneAppearance& appearance,
                                         const TextureEdgeOptions& options) {
  // Each texture is vectorised once, in metres on the texture (x right, y down).
  std::vector<std::vector<TexelSegment>> per_texture(appearance.textureCount());
  std::vector<bool> done(appearance.textureCount(), false);
  std::vector<SceneEdge> out;
  const auto& quads = scene.quads();
  for (std::size_t qi = 0; qi < quads.size(); ++qi) {
    const SceneQuad& q = quads[qi];
    const TextureSpec& spec = scene.materials()[q.material].texture;
    if (spec.pattern == "plain") continue;
    const SceneAppearance::Mapping& m = appearance.mapping(static_cast<int>(qi));
    const Texture& texture = appearance.texture(m.texture);
    if (!done[m.texture]) {
      per_texture[m.texture] = detectTextureEdges(texture, texture.texelSize(), options);
      done[m.texture] = true;
    }
    const std::vector<TexelSegment>& segments = per_texture[m.texture];
    if (segments.empty()) continue;

    // The renderer's mapping (RadianceRenderer): texel x = (s + offset_x) / texel and
    // y = (t + offset_y) / texel, with s along edge_u and t = |edge_v| - b (swapped: s along
    // edge_v and t = |edge_u| - a). So the quad covers [offset, offset + size] in texture
    // metres, and a repeating texture is laid once per period.
    const double texel = 1.0 / m.inv_texel;
    const double length_u = q.edge_u.norm(), length_v = q.edge_v.norm();
    const Eigen::Vector3d u = q.edge_u / length_u, v = q.edge_v / length_v;
    const Eigen::Vector2d size =
        m.swap ? Eigen::Vector2d(length_v, length_u) : Eigen::Vector2d(length_u, length_v);
    const Eigen::Vector2d lo(m.offset_x, m.offset_y), hi = lo + size;
    const Eigen::Vector2d period(texture.width() * texel, texture.height() * texel);
    const bool repeat = !spec.uniquePerSurface();
    const int kx0 = repeat ? static_cast<int>(std::floor(lo.x() / period.x())) : 0;
    const int kx1 = repeat ? static_cast<int>(std::floor(hi.x() / period.x())) : 0;
    const int ky0 = repeat ? static_cast<int>(std::floor(lo.y() / period.y())) : 0;
    const int ky1 = repeat ? static_cast<int>(std::floor(hi.y() / period.y())) : 0;
    auto to3d = [&](const Eigen::Vector2d& p) {
      const double s = p.x() - m.offset_x, t = p.y() - m.offset_y;
      const double a = m.swap ? length_u - t : s;
      const double b = m.swap ? s : length_v - t;
      return Eigen::Vector3d(q.origin + a * u + b * v);
    };
    for (int ky = ky0; ky <= ky1; ++ky)
      for (int kx = kx0; kx <= kx1; ++kx) {
        const Eigen::Vector2d shift(kx * period.x(), ky * period.y());
        for (const TexelSegment& seg : segments) {
          LineSegment piece(Eigen::Vector2d(seg.x0, seg.y0) * texel + shift,
                            Eigen::Vector2d(seg.x1, seg.y1) * texel + shift);
          bool clipped = false;
          if (!clipSegmentToRect(&piece, lo.x(), lo.y(), hi.x(), hi.y(), &clipped) ||
              piece.length() < options.min_length_m)
            continue;
          const Eigen::Vector2d &a = piece.start, &b = piece.end;
          SceneEdge e;
          e.id = static_cast<int>(out.size());
          e.a = to3d(a);
          e.b = to3d(b);
          e.object = q.object;
          out.push_back(e);
        }
      }
  }
  return out;
}

}  // namespace alvio::sim
