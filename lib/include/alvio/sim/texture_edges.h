#pragma once
// The straight albedo edges painted on the scene's surfaces: brick and tile joints, panel
// seams, hazard stripes, poster shapes. A line tracker finds them as readily as the
// geometry's edges, but Scene::edges() holds only the latter, so an evaluation against it
// counts a correctly mapped brick joint as wrong. These are the texture half of the truth.
//
// They come from the noise-free textures themselves (level 0, before lighting, blur or
// sensor noise): each texture is vectorised with LSD, a segment is kept when it is long
// enough and separates two albedos that differ by enough, and the kept segments are laid
// on every surface that shows the texture (tile by tile for the shared repeating textures,
// clipped to the surface) with the renderer's own texture mapping. A straight edge that
// crosses a repeating texture's border is found as two pieces, or not at all when they
// are short: the truth errs towards missing texture edges, never towards inventing them.

#include <vector>

#include "alvio/sim/scene.h"
#include "alvio/sim/scene_appearance.h"

namespace alvio::sim {

struct TextureEdgeOptions {
  double min_length_m = 0.10;  ///< shorter albedo edges (on the surface) are left out
  /// Mean albedo difference (0..1) between the two sides of a segment, sampled
  /// `contrast_offset_texels` to either side; weaker edges are left out.
  double min_contrast = 0.10;
  double contrast_offset_texels = 1.5;
};

/// One straight albedo edge of one texture, in level-0 texel coordinates (texel centres
/// at +0.5, as Texture::sample takes them).
struct TexelSegment {
  float x0, y0, x1, y1;
  float contrast;  ///< mean albedo step across it
};

/// The straight albedo edges of `texture` that pass `options` (`texel_m`: its texel size).
std::vector<TexelSegment> detectTextureEdges(const Texture& texture, double texel_m,
                                             const TextureEdgeOptions& options = {});

/// Every surface's texture edges as 3D segments in the scene's frame. `SceneEdge::object`
/// is the surface's object; `id` counts from 0 in output order. `appearance` must have been
/// built from `scene` with the texture density and seed of the rendering being judged.
std::vector<SceneEdge> sceneTextureEdges(const Scene& scene, const SceneAppearance& appearance,
                                         const TextureEdgeOptions& options = {});

}  // namespace alvio::sim
