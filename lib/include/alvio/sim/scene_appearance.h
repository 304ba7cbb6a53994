#pragma once
// What the renderer needs besides geometry: a texture per surface (generated
// from the materials for a texture density and seed) and a light map per
// surface. Lighting has no sharp features (point lights, ambient, soft
// shadows), so it is baked once into coarse per-quad grids, with shadow rays,
// and interpolated at render time: a lookup per pixel instead of a sum over
// lights.

#include <cstdint>
#include <vector>

#include "alvio/sim/procedural_texture.h"
#include "alvio/sim/scene.h"

namespace alvio::sim {

struct AppearanceOptions {
  double texture_density = 1.0;  ///< 1 rich .. 0 plain (see parseTextureDensity)
  uint64_t seed = 1;             ///< mixed with the scene's texture_seed
  double light_map_cell_m = 0.25;
  bool shadows = true;
  /// Rays per light-map sample for ambient occlusion (0 = none): corners and the
  /// space under shelves get darker, as in real rooms.
  int occlusion_rays = 12;
  int threads = 1;
};

class SceneAppearance {
 public:
  SceneAppearance(const Scene& scene, const AppearanceOptions& options);

  /// How quad i maps its (a, b) metres to texture texels.
  struct Mapping {
    int texture = 0;
    bool swap = false;  ///< texture x follows edge_v (edge_u is the more vertical one)
    float offset_x = 0, offset_y = 0;  ///< metres
    float inv_texel = 100.0f;
    float emissive = 0.0f;
  };
  /// A grid of irradiance values over quad i (cells of about light_map_cell_m).
  struct LightMap {
    int nu = 1, nv = 1;
    std::vector<float> front, back;  ///< back: for two-sided quads seen from behind
    float irradiance(bool back_side, float a, float b) const;  ///< a, b in [0, 1]
  };

  const Texture& texture(int i) const { return textures_[i]; }
  const Mapping& mapping(int quad) const { return mappings_[quad]; }
  const LightMap& lightMap(int quad) const { return light_maps_[quad]; }
  int textureCount() const { return static_cast<int>(textures_.size()); }

 private:
  std::vector<Texture> textures_;
  std::vector<Mapping> mappings_;
  std::vector<LightMap> light_maps_;
};

}  // namespace alvio::sim
