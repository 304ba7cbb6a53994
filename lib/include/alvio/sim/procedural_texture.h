#pragma once
// Procedural surface textures (albedo in [0, 1]): multi-scale gradient noise,
// concrete, bricks, tiles, metal panels, wooden planks, hazard stripes and
// posters with shapes and text. All are deterministic for a seed. Shared
// textures tile seamlessly, so large surfaces can repeat them with offsets.
//
// The density knob (0..1) scales everything that makes a surface "textured"
// (grain, pits, joints, seams, stripes, stains, poster contents): at 1 surfaces
// are rich in corners, near 0 they become plain and only the geometry's edges,
// the shading and some smooth large-scale variation remain.

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace alvio::sim {

struct TextureSpec {
  /// plain | noise | concrete | bricks | tiles | metal | wood | stripes | poster | checker
  std::string pattern = "noise";
  double albedo = 0.5;      ///< mean reflectance
  double contrast = 0.3;    ///< amplitude of the variation around the mean
  double texel_m = 0.01;    ///< size of one texel on the surface
  double feature_m = 0.5;   ///< brick length, tile / panel / checker size, plank width, noise scale
  int texture_size = 1024;  ///< texels per side of a shared (tiling) texture; power of two
  /// > 0: the surface glows with this radiance regardless of the lights (lamps, windows).
  double emissive = 0.0;
  /// Posters get their own texture per surface instead of one shared tiling texture.
  bool uniquePerSurface() const { return pattern == "poster"; }
  /// Throws alvio::Error (prefixed by `where`) on an unknown pattern or bad values.
  void validate(const std::string& where) const;
};

/// Known pattern names, for messages.
const std::vector<std::string>& texturePatterns();

/// A texture with its mip-map pyramid; sampled bilinearly within a level and
/// linearly between levels (trilinear), repeating or clamped at the border.
/// Stored with 8 bits per texel: four times less memory traffic than floats, and
/// the albedo steps (1/255) stay below the sensor noise.
class Texture {
 public:
  Texture() = default;
  /// A repeating texture must have power-of-two width and height.
  Texture(const cv::Mat1f& albedo, double texel_m, bool repeat);

  int width() const { return levels_.empty() ? 0 : levels_[0].cols; }
  int height() const { return levels_.empty() ? 0 : levels_[0].rows; }
  double texelSize() const { return texel_m_; }
  const cv::Mat1b& level(int i) const { return levels_[i]; }
  int levels() const { return static_cast<int>(levels_.size()); }

  /// Albedo at (x, y) in level-0 texels (x right, y down; texel centres at +0.5),
  /// averaged over a footprint of about `footprint` texels.
  float sample(float x, float y, float footprint) const {
    const float level = footprint > 1.0f ? fastLog2(footprint) : 0.0f;
    const float max_level = static_cast<float>(levels_.size() - 1);
    if (level >= max_level) return bilinear(levels_.size() - 1, x, y);
    const int l0 = static_cast<int>(level);
    const float f = level - static_cast<float>(l0);
    const float v0 = bilinear(l0, x, y);
    if (f < 1e-3f) return v0;
    return v0 + f * (bilinear(l0 + 1, x, y) - v0);
  }

 private:
  // log2 to about 0.02 (exponent bits plus a quadratic for the mantissa): it only
  // chooses the mip level, where such an error is invisible.
  static float fastLog2(float x) {
    int e;
    const float m = std::frexp(x, &e);  // x = m 2^e, m in [0.5, 1)
    return static_cast<float>(e) - 1.0f + (-0.34484843f * (2 * m) + 2.02466578f) * (2 * m) -
           1.65677798f;
  }
  float bilinear(std::size_t level, float x, float y) const {
    const cv::Mat1b& m = levels_[level];
    const float s = 1.0f / static_cast<float>(1 << level);
    const float fx = x * s - 0.5f, fy = y * s - 0.5f;
    const float x0f = std::floor(fx), y0f = std::floor(fy);
    const float ax = fx - x0f, ay = fy - y0f;
    int x0 = static_cast<int>(x0f), y0 = static_cast<int>(y0f);
    int x1 = x0 + 1, y1 = y0 + 1;
    if (repeat_) {
      // Repeating textures have power-of-two sizes at every level: wrap by masking.
      const int mx = m.cols - 1, my = m.rows - 1;
      x0 &= mx;
      x1 &= mx;
      y0 &= my;
      y1 &= my;
    } else {
      x0 = clampInt(x0, m.cols);
      x1 = clampInt(x1, m.cols);
      y0 = clampInt(y0, m.rows);
      y1 = clampInt(y1, m.rows);
    }
    const uint8_t* r0 = m.ptr<uint8_t>(y0);
    const uint8_t* r1 = m.ptr<uint8_t>(y1);
    const float a00 = r0[x0], a01 = r0[x1], a10 = r1[x0], a11 = r1[x1];
    const float top = a00 + ax * (a01 - a00);
    const float bottom = a10 + ax * (a11 - a10);
    return (top + ay * (bottom - top)) * (1.0f / 255.0f);
  }
  static int clampInt(int i, int n) { return i < 0 ? 0 : (i >= n ? n - 1 : i); }

  std::vector<cv::Mat1b> levels_;
  double texel_m_ = 0.01;
  bool repeat_ = true;
};

/// The albedo image of a pattern: `width` x `height` texels. Shared patterns tile
/// seamlessly when width and height are multiples of their feature periods (the
/// generator rounds periods to make this so).
cv::Mat1f generateTextureImage(const TextureSpec& spec, int width, int height, double density,
                               uint64_t seed);

/// Texture-density presets: "rich" 1.0, "medium" 0.5, "poor" 0.08; or a number in [0, 1].
double parseTextureDensity(const std::string& text);

}  // namespace alvio::sim
