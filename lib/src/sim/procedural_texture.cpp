#include "alvio/sim/procedural_texture.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

#include "alvio/common/error.h"
#include "alvio/sim/seeded_random.h"

namespace alvio::sim {
namespace {

// Gradient (Perlin-style) noise on an integer lattice that repeats every (px, py)
// cells, so that textures built from it tile without seams.
class PeriodicNoise {
 public:
  explicit PeriodicNoise(uint64_t seed)
      : seed32_(static_cast<uint32_t>(mixSeed(seed, 0x7777) & 0xffffffffu)) {}

  /// In about [-1, 1].
  float at(float x, float y, int px, int py) const {
    const float fx = std::floor(x), fy = std::floor(y);
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    const float dx = x - fx, dy = y - fy;
    const float ux = fade(dx), uy = fade(dy);
    const float g00 = grad(ix, iy, px, py, dx, dy);
    const float g10 = grad(ix + 1, iy, px, py, dx - 1, dy);
    const float g01 = grad(ix, iy + 1, px, py, dx, dy - 1);
    const float g11 = grad(ix + 1, iy + 1, px, py, dx - 1, dy - 1);
    const float a = g00 + ux * (g10 - g00);
    const float b = g01 + ux * (g11 - g01);
    return 1.41f * (a + uy * (b - a));
  }

  /// Fractal sum of `octaves` octaves starting at `cells` lattice cells across the
  /// texture (u, v in [0, 1) of the texture); each octave doubles the frequency.
  float fbm(float u, float v, int cells_x, int cells_y, int octaves, float gain = 0.5f) const {
    float sum = 0, amp = 1, norm = 0;
    for (int o = 0; o < octaves; ++o) {
      const int cx = cells_x << o, cy = cells_y << o;
      sum += amp * at(u * cx, v * cy, cx, cy);
      norm += amp;
      amp *= gain;
    }
    return sum / norm;
  }

 private:
  static float fade(float t) { return t * t * t * (t * (t * 6 - 15) + 10); }
  float grad(int ix, int iy, int px, int py, float dx, float dy) const {
    ix %= px;
    iy %= py;
    if (ix < 0) ix += px;
    if (iy < 0) iy += py;
    // A cheap 32-bit integer hash of the lattice point (quality is ample for noise).
    uint32_t h =
        static_cast<uint32_t>(ix) * 0x27d4eb2du ^ static_cast<uint32_t>(iy) * 0x165667b1u ^ seed32_;
    h ^= h >> 15;
    h *= 0x2c1b3c6du;
    h ^= h >> 12;
    h *= 0x297a2d39u;
    h ^= h >> 15;
    static const float kDirs[16][2] = {
        {1, 0},  {0.9239f, 0.3827f},   {0.7071f, 0.7071f},   {0.3827f, 0.9239f},
        {0, 1},  {-0.3827f, 0.9239f},  {-0.7071f, 0.7071f},  {-0.9239f, 0.3827f},
        {-1, 0}, {-0.9239f, -0.3827f}, {-0.7071f, -0.7071f}, {-0.3827f, -0.9239f},
        {0, -1}, {0.3827f, -0.9239f},  {0.7071f, -0.7071f},  {0.9239f, -0.3827f}};
    const float* g = kDirs[h & 15];
    return g[0] * dx + g[1] * dy;
  }
  uint32_t seed32_;
};

int cellsAcross(double size_m, double feature_m) {
  return std::max(1, static_cast<int>(std::lround(size_m / std::max(feature_m, 1e-6))));
}

// Fill every texel with f(x, y, u, v) (texel indices and fractions of the texture).
template <typename F>
void fill(cv::Mat1f& img, F&& f) {
  const float iw = 1.0f / img.cols, ih = 1.0f / img.rows;
  for (int y = 0; y < img.rows; ++y) {
    float* row = img.ptr<float>(y);
    for (int x = 0; x < img.cols; ++x) row[x] = f(x, y, (x + 0.5f) * iw, (y + 0.5f) * ih);
  }
}

// Draw with OpenCV on 8 bits, then add the result (scaled to [-1, 1]) to the albedo.
void addDrawing(cv::Mat1f& img, const cv::Mat1b& drawing, float amplitude) {
  for (int y = 0; y < img.rows; ++y) {
    float* d = img.ptr<float>(y);
    const uint8_t* s = drawing.ptr<uint8_t>(y);
    for (int x = 0; x < img.cols; ++x) d[x] += amplitude * (s[x] - 128) / 127.0f;
  }
}

// Small dark or light dots (pits, bolt heads, tie holes), wrapped around the border.
void addDots(cv::Mat1b& canvas, SeededRandom& rng, int count, double r_min, double r_max,
             uint8_t value) {
  for (int i = 0; i < count; ++i) {
    const cv::Point c(rng.uniformInt(0, canvas.cols - 1), rng.uniformInt(0, canvas.rows - 1));
    const int r = std::max(1, static_cast<int>(std::lround(rng.uniform(r_min, r_max))));
    for (int ox = -1; ox <= 1; ++ox)
      for (int oy = -1; oy <= 1; ++oy)
        cv::circle(canvas, c + cv::Point(ox * canvas.cols, oy * canvas.rows), r, value, cv::FILLED,
                   cv::LINE_AA);
  }
}

cv::Mat1f concrete(const TextureSpec& s, int w, int h, double density, uint64_t seed) {
  const PeriodicNoise noise(seed);
  const double size_x = w * s.texel_m, size_y = h * s.texel_m;
  const int stain_x = cellsAcross(size_x, 4 * s.feature_m),
            stain_y = cellsAcross(size_y, 4 * s.feature_m);
  const int grain_x = std::max(1, w / 6), grain_y = std::max(1, h / 6);
  const float c = static_cast<float>(s.contrast);
  const float d = static_cast<float>(density);
  const float low = c * std::max(0.35f, d);  // large stains survive low density: no corners
  cv::Mat1f img(h, w);
  fill(img, [&](int, int, float u, float v) {
    return static_cast<float>(s.albedo) + 0.6f * low * noise.fbm(u, v, stain_x, stain_y, 5) +
           0.25f * c * d * noise.fbm(u + 0.37f, v + 0.11f, grain_x, grain_y, 2);
  });
  // Formwork: panel seams and tie holes, the typical marks of cast concrete walls.
  cv::Mat1b marks(h, w, uint8_t(128));
  const int panels_x = cellsAcross(size_x, 2 * s.feature_m);
  const int panels_y = cellsAcross(size_y, s.feature_m);
  SeededRandom rng(mixSeed(seed, 5));
  // Seams (formwork joints on walls, saw-cut joints on floors) widen with the panel size.
  const double seam_m = std::clamp(0.005 * s.feature_m, 0.006, 0.02);
  const int seam = std::max(1, static_cast<int>(std::lround(seam_m / s.texel_m)));
  for (int i = 0; i <= panels_x; ++i) {
    const int x = i * w / panels_x;
    cv::line(marks, {x, 0}, {x, h}, 128 - 70, seam, cv::LINE_AA);
  }
  for (int j = 0; j <= panels_y; ++j) {
    const int y = j * h / panels_y;
    cv::line(marks, {0, y}, {w, y}, 128 - 60, seam, cv::LINE_AA);
  }
  const double hole_r = 0.012 / s.texel_m;
  for (int i = 0; i < panels_x; ++i)
    for (int j = 0; j < panels_y; ++j)
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 2; ++b) {
          const int x = static_cast<int>((i + (a + 0.5) / 3.0) * w / panels_x);
          const int y = static_cast<int>((j + (b + 0.5) / 2.0) * h / panels_y);
          cv::circle(marks, {x, y}, std::max(1, static_cast<int>(hole_r)), 128 - 110, cv::FILLED,
                     cv::LINE_AA);
        }
  const int pits = static_cast<int>(size_x * size_y * 6);
  addDots(marks, rng, pits, 0.004 / s.texel_m, 0.012 / s.texel_m, 128 - 70);
  addDots(marks, rng, pits / 3, 0.01 / s.texel_m, 0.03 / s.texel_m, 128 + 50);
  // Stains (oil, water, patches): fewer and larger, soft.
  cv::Mat1b stains(h, w, uint8_t(128));
  for (int i = 0, n = static_cast<int>(size_x * size_y * 0.12); i < n; ++i) {
    // Elongated, of random darkness: oil drips, tyre marks, patches.
    const cv::Point c(rng.uniformInt(0, w - 1), rng.uniformInt(0, h - 1));
    const cv::Size axes(static_cast<int>(rng.uniform(0.05, 0.4) / s.texel_m),
                        static_cast<int>(rng.uniform(0.03, 0.15) / s.texel_m));
    const double angle = rng.uniform(0, 180);
    const uint8_t value = static_cast<uint8_t>(128 - rng.uniformInt(15, 70));
    for (int ox = -1; ox <= 1; ++ox)
      for (int oy = -1; oy <= 1; ++oy)
        cv::ellipse(stains, c + cv::Point(ox * w, oy * h), axes, angle, 0, 360, value, cv::FILLED,
                    cv::LINE_AA);
  }
  {
    // Blur with wrap-around so the texture still tiles without a seam.
    const int pad = static_cast<int>(std::ceil(0.08 / s.texel_m));
    cv::Mat1b padded;
    cv::copyMakeBorder(stains, padded, pad, pad, pad, pad, cv::BORDER_WRAP);
    cv::GaussianBlur(padded, padded, cv::Size(0, 0), 0.02 / s.texel_m);
    padded(cv::Rect(pad, pad, w, h)).copyTo(stains);
  }
  addDrawing(img, stains, c * d);
  addDrawing(img, marks, c * d);
  return img;
}

cv::Mat1f bricks(const TextureSpec& s, int w, int h, double density, uint64_t seed) {
  const PeriodicNoise noise(seed);
  const double size_x = w * s.texel_m, size_y = h * s.texel_m;
  const int per_row = cellsAcross(size_x, s.feature_m);
  int rows = cellsAcross(size_y, s.feature_m / 3.3);
  rows += rows % 2;  // running bond repeats every two rows
  const float brick_w = static_cast<float>(w) / per_row, brick_h = static_cast<float>(h) / rows;
  const float mortar = static_cast<float>(0.011 / s.texel_m);
  const float c = static_cast<float>(s.contrast), d = static_cast<float>(density);
  const int gx = std::max(1, w / 8), gy = std::max(1, h / 8);
  const int sx = cellsAcross(size_x, 3.0), sy = cellsAcross(size_y, 3.0);
  cv::Mat1f img(h, w);
  fill(img, [&](int x, int y, float u, float v) {
    const int row = static_cast<int>(y / brick_h);
    const float shift = (row % 2) * 0.5f * brick_w;
    float bx = x + 0.5f - shift;
    bx -= std::floor(bx / w) * w;
    const int col = static_cast<int>(bx / brick_w);
    const float ex = std::min(bx - col * brick_w, (col + 1) * brick_w - bx);
    const float ey = std::min(y + 0.5f - row * brick_h, (row + 1) * brick_h - y - 0.5f);
    const uint64_t id = mixSeed(seed, (row % rows) * 1000 + (col % per_row));
    const float tone = static_cast<float>((id % 1000) / 1000.0 - 0.5);
    // Mortar joints are lighter and soft-edged (a texel of anti-aliasing).
    const float joint = std::clamp((mortar * 0.5f - std::min(ex, ey)) + 0.5f, 0.0f, 1.0f);
    const float brick = static_cast<float>(s.albedo) + c * d * 0.5f * tone +
                        0.2f * c * d * noise.fbm(u, v, gx, gy, 2);
    // Written so that density 1 gives the same value as ever; the joints fade with it.
    const float mortar_v = static_cast<float>(s.albedo) + c * (0.3f * d + 0.4f * d);
    return (1 - joint) * brick + joint * mortar_v + 0.3f * c * noise.fbm(u, v, sx, sy, 3);
  });
  return img;
}

cv::Mat1f tiles(const TextureSpec& s, int w, int h, double density, uint64_t seed) {
  const PeriodicNoise noise(seed);
  const double size_x = w * s.texel_m, size_y = h * s.texel_m;
  const int nx = cellsAcross(size_x, s.feature_m), ny = cellsAcross(size_y, s.feature_m);
  const float tw = static_cast<float>(w) / nx, th = static_cast<float>(h) / ny;
  const float grout = static_cast<float>(0.005 / s.texel_m);
  const float c = static_cast<float>(s.contrast), d = static_cast<float>(density);
  const int gx = std::max(1, w / 16), gy = std::max(1, h / 16);
  const int sx = cellsAcross(size_x, 2.0), sy = cellsAcross(size_y, 2.0);
  cv::Mat1f img(h, w);
  fill(img, [&](int x, int y, float u, float v) {
    const int col = static_cast<int>((x + 0.5f) / tw), row = static_cast<int>((y + 0.5f) / th);
    const float ex = std::min(x + 0.5f - col * tw, (col + 1) * tw - x - 0.5f);
    const float ey = std::min(y + 0.5f - row * th, (row + 1) * th - y - 0.5f);
    const float joint = std::clamp((grout * 0.5f - std::min(ex, ey)) + 0.5f, 0.0f, 1.0f);
    const float tone = static_cast<float>((mixSeed(seed, row * 7919 + col) % 1000) / 1000.0 - 0.5);
    const float tile = static_cast<float>(s.albedo) + c * d * 0.35f * tone +
                       0.15f * c * d * noise.fbm(u, v, gx, gy, 2);
    return (1 - joint) * tile + joint * (static_cast<float>(s.albedo) - c * d * 0.8f) +
           0.35f * c * std::max(0.3f, d) * noise.fbm(u, v, sx, sy, 4);
  });
  return img;
}

cv::Mat1f metal(const TextureSpec& s, int w, int h, double density, uint64_t seed) {
  const PeriodicNoise noise(seed);
  const double size_x = w * s.texel_m, size_y = h * s.texel_m;
  const float c = static_cast<float>(s.contrast), d = static_cast<float>(density);
  const int bx = cellsAcross(size_x, 1.5), by = std::max(1, h / 3);  // brushed: long streaks
  const int sx = cellsAcross(size_x, 2 * s.feature_m), sy = cellsAcross(size_y, 2 * s.feature_m);
  cv::Mat1f img(h, w);
  fill(img, [&](int, int, float u, float v) {
    return static_cast<float>(s.albedo) + 0.25f * c * d * noise.fbm(u, v, bx, by, 2) +
           0.5f * c * std::max(0.3f, d) * noise.fbm(u + 0.5f, v, sx, sy, 4);
  });
  cv::Mat1b marks(h, w, uint8_t(128));
  const int nx = cellsAcross(size_x, s.feature_m), ny = cellsAcross(size_y, 2 * s.feature_m);
  const int seam = std::max(1, static_cast<int>(std::lround(0.005 / s.texel_m)));
  const int rivet = std::max(1, static_cast<int>(std::lround(0.008 / s.texel_m)));
  const int pitch = std::max(4, static_cast<int>(std::lround(0.15 / s.texel_m)));
  for (int i = 0; i <= nx; ++i) {
    const int x = i * w / nx;
    cv::line(marks, {x, 0}, {x, h}, 20, seam, cv::LINE_AA);
    for (int y = pitch / 2; y < h; y += pitch) {
      cv::circle(marks, {x + 3 * rivet, y}, rivet, 230, cv::FILLED, cv::LINE_AA);
      cv::circle(marks, {x - 3 * rivet, y}, rivet, 230, cv::FILLED, cv::LINE_AA);
    }
  }
  for (int j = 0; j <= ny; ++j)
    cv::line(marks, {0, j * h / ny}, {w, j * h / ny}, 30, seam, cv::LINE_AA);
  SeededRandom rng(mixSeed(seed, 9));
  addDots(marks, rng, static_cast<int>(size_x * size_y * 6), 0.01 / s.texel_m, 0.05 / s.texel_m,
          70);  // scuffs and stains
  addDrawing(img, marks, c * d);
  return img;
}

cv::Mat1f wood(const TextureSpec& s, int w, int h, double density, uint64_t seed) {
  const PeriodicNoise noise(seed);
  const double size_x = w * s.texel_m, size_y = h * s.texel_m;
  const int planks = cellsAcross(size_y, s.feature_m);
  const float ph = static_cast<float>(h) / planks;
  const float gap = static_cast<float>(0.006 / s.texel_m);
  const float c = static_cast<float>(s.contrast), d = static_cast<float>(density);
  const int grain_x = cellsAcross(size_x, 0.6), grain_y = std::max(1, h / 4);
  cv::Mat1f img(h, w);
  fill(img, [&](int, int y, float u, float v) {
    const int p = static_cast<int>((y + 0.5f) / ph);
    const float e = std::min(y + 0.5f - p * ph, (p + 1) * ph - y - 0.5f);
    const float joint = std::clamp(gap * 0.5f - e + 0.5f, 0.0f, 1.0f);
    const float tone = static_cast<float>((mixSeed(seed, p) % 1000) / 1000.0 - 0.5);
    const float grain = noise.fbm(u + 0.13f * p, v, grain_x, grain_y, 3);
    const float board = static_cast<float>(s.albedo) + c * d * (0.4f * tone + 0.5f * grain);
    return (1 - joint) * board + joint * (static_cast<float>(s.albedo) - c * (0.3f * d + 0.7f * d));
  });
  return img;
}

cv::Mat1f stripes(const TextureSpec& s, int w, int h, double density, uint64_t seed) {
  const PeriodicNoise noise(seed);
  const double size_x = w * s.texel_m, size_y = h * s.texel_m;
  // Diagonal stripes that tile: an integer number of periods along x and y.
  const int nx = cellsAcross(size_x, s.feature_m), ny = cellsAcross(size_y, s.feature_m);
  const float c = static_cast<float>(s.contrast), d = static_cast<float>(density);
  const int dx = cellsAcross(size_x, 0.5), dy = cellsAcross(size_y, 0.5);
  cv::Mat1f img(h, w);
  fill(img, [&](int, int, float u, float v) {
    const float phase = u * nx + v * ny;
    const float f = phase - std::floor(phase);
    // Soft edges (about one texel) so that the stripes do not alias.
    const float edge = 0.5f * nx / w + 0.5f * ny / h;
    const float on = std::clamp((std::min(f, 1 - f) - 0.25f) / edge + 0.5f, 0.0f, 1.0f);
    return static_cast<float>(s.albedo) + c * d * (on - 0.5f) * 2.0f +
           0.2f * c * noise.fbm(u, v, dx, dy, 4);
  });
  return img;
}

cv::Mat1f checker(const TextureSpec& s, int w, int h, double density, uint64_t) {
  const int nx = cellsAcross(w * s.texel_m, s.feature_m),
            ny = cellsAcross(h * s.texel_m, s.feature_m);
  const float c = static_cast<float>(s.contrast * density);
  cv::Mat1f img(h, w);
  fill(img, [&](int, int, float u, float v) {
    const int k = static_cast<int>(u * nx) + static_cast<int>(v * ny);
    return static_cast<float>(s.albedo) + (k % 2 ? c : -c);
  });
  return img;
}

cv::Mat1f noiseTexture(const TextureSpec& s, int w, int h, double density, uint64_t seed) {
  const PeriodicNoise noise(seed);
  const int cx = cellsAcross(w * s.texel_m, s.feature_m),
            cy = cellsAcross(h * s.texel_m, s.feature_m);
  const float c = static_cast<float>(s.contrast), d = static_cast<float>(density);
  cv::Mat1f img(h, w);
  fill(img, [&](int, int, float u, float v) {
    return static_cast<float>(s.albedo) + c * (std::max(d, 0.3f) * noise.fbm(u, v, cx, cy, 2) +
                                               d * 0.6f * noise.fbm(u, v, 4 * cx, 4 * cy, 4));
  });
  return img;
}

const char* kWords[] = {"SAFETY",  "FIRST", "EXIT",    "ZONE", "B12",   "DANGER",  "HIGH",
                        "VOLTAGE", "NO",    "ENTRY",   "LAB",  "ASL",   "ETH",     "FLOW",
                        "PUMP",    "VALVE", "LEVEL 2", "KEEP", "CLEAR", "MACHINE", "HALL",
                        "MAX",     "LOAD",  "500 kg",  "AREA", "FIRE",  "ALARM",   "TEST"};

cv::Mat1f poster(const TextureSpec& s, int w, int h, double density, uint64_t seed) {
  SeededRandom rng(seed);
  const bool dark = rng.uniform() < 0.3;
  const double bg = dark ? 0.15 : std::min(0.95, s.albedo + 0.3);
  cv::Mat1b canvas(h, w, static_cast<uint8_t>(bg * 255));
  const uint8_t ink = dark ? 230 : 25;
  const int elements = static_cast<int>(std::lround(14 * density));
  if (density >= 0.25) {
    // Border and header band.
    const int margin = std::max(2, w / 25);
    cv::rectangle(canvas, {margin, margin}, {w - margin, h - margin}, ink, std::max(1, w / 120),
                  cv::LINE_AA);
    const int band = h / 6;
    cv::rectangle(canvas, {margin, margin}, {w - margin, margin + band}, ink, cv::FILLED,
                  cv::LINE_AA);
    const double title_scale = band / 40.0;
    cv::putText(canvas, kWords[rng.uniformInt(0, 27)], {2 * margin, margin + band * 3 / 4},
                cv::FONT_HERSHEY_DUPLEX, title_scale, 255 - ink, std::max(1, band / 12),
                cv::LINE_AA);
  }
  for (int i = 0; i < elements; ++i) {
    const int kind = rng.uniformInt(0, 4);
    const cv::Point c(rng.uniformInt(w / 10, 9 * w / 10), rng.uniformInt(h / 4, 9 * h / 10));
    const int r = rng.uniformInt(std::max(3, w / 30), std::max(4, w / 7));
    const uint8_t tone = static_cast<uint8_t>(rng.uniformInt(0, 1) ? ink : rng.uniformInt(60, 200));
    if (kind == 0) {
      cv::circle(canvas, c, r, tone, rng.uniform() < 0.5 ? cv::FILLED : std::max(1, r / 6),
                 cv::LINE_AA);
    } else if (kind == 1) {
      cv::rectangle(canvas, c - cv::Point(r, r / 2), c + cv::Point(r, r / 2), tone,
                    rng.uniform() < 0.5 ? cv::FILLED : std::max(1, r / 8), cv::LINE_AA);
    } else if (kind == 2) {
      const std::vector<cv::Point> tri = {c + cv::Point(0, -r), c + cv::Point(r, r * 3 / 4),
                                          c + cv::Point(-r, r * 3 / 4)};
      cv::fillPoly(canvas, std::vector<std::vector<cv::Point>>{tri}, tone, cv::LINE_AA);
    } else {
      // A few lines of text.
      const double scale = std::max(0.3, h / 400.0 * rng.uniform(0.6, 1.4));
      for (int l = 0; l < 3; ++l)
        cv::putText(canvas, kWords[rng.uniformInt(0, 27)],
                    c + cv::Point(-r, static_cast<int>(l * 30 * scale)), cv::FONT_HERSHEY_SIMPLEX,
                    scale, ink, std::max(1, static_cast<int>(2 * scale)), cv::LINE_AA);
    }
  }
  cv::Mat1f img;
  canvas.convertTo(img, CV_32F, 1.0 / 255.0);
  return img;
}

}  // namespace

const std::vector<std::string>& texturePatterns() {
  static const std::vector<std::string> names = {"plain", "noise", "concrete", "bricks", "tiles",
                                                 "metal", "wood",  "stripes",  "poster", "checker"};
  return names;
}

void TextureSpec::validate(const std::string& where) const {
  const auto& names = texturePatterns();
  if (std::find(names.begin(), names.end(), pattern) == names.end()) {
    std::string known;
    for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
    throw Error(where + ": unknown texture pattern '" + pattern + "' (known: " + known + ")");
  }
  if (!(texel_m > 0) || !(feature_m > 0))
    throw Error(where + ": texel_m and feature_m must be positive");
  if (albedo < 0 || albedo > 1) throw Error(where + ": albedo must be in [0, 1]");
  if (texture_size < 8 || (texture_size & (texture_size - 1)) != 0)
    throw Error(where + ": texture_size must be a power of two >= 8");
}

Texture::Texture(const cv::Mat1f& albedo, double texel_m, bool repeat)
    : texel_m_(texel_m), repeat_(repeat) {
  auto power_of_two = [](int n) { return n > 0 && (n & (n - 1)) == 0; };
  if (repeat && (!power_of_two(albedo.cols) || !power_of_two(albedo.rows)))
    throw Error("a repeating texture needs power-of-two sizes, got " + std::to_string(albedo.cols) +
                "x" + std::to_string(albedo.rows));
  cv::Mat1b level0;
  albedo.convertTo(level0, CV_8U, 255.0);  // rounds and saturates
  levels_.push_back(level0);
  while (levels_.back().cols > 1 && levels_.back().rows > 1 && levels_.size() < 14) {
    const cv::Mat1b& prev = levels_.back();
    cv::Mat1b next;
    cv::resize(prev, next, cv::Size((prev.cols + 1) / 2, (prev.rows + 1) / 2), 0, 0,
               cv::INTER_AREA);
    levels_.push_back(next);
  }
}

cv::Mat1f generateTextureImage(const TextureSpec& spec, int width, int height, double density,
                               uint64_t seed) {
  density = std::clamp(density, 0.0, 1.0);
  cv::Mat1f img;
  const std::string& p = spec.pattern;
  if (p == "plain") {
    img = cv::Mat1f(height, width, static_cast<float>(spec.albedo));
  } else if (p == "noise") {
    img = noiseTexture(spec, width, height, density, seed);
  } else if (p == "concrete") {
    img = concrete(spec, width, height, density, seed);
  } else if (p == "bricks") {
    img = bricks(spec, width, height, density, seed);
  } else if (p == "tiles") {
    img = tiles(spec, width, height, density, seed);
  } else if (p == "metal") {
    img = metal(spec, width, height, density, seed);
  } else if (p == "wood") {
    img = wood(spec, width, height, density, seed);
  } else if (p == "stripes") {
    img = stripes(spec, width, height, density, seed);
  } else if (p == "poster") {
    img = poster(spec, width, height, density, seed);
  } else if (p == "checker") {
    img = checker(spec, width, height, density, seed);
  } else {
    throw Error("unknown texture pattern '" + p + "'");
  }
  cv::min(img, 1.0, img);
  cv::max(img, 0.0, img);
  return img;
}

double parseTextureDensity(const std::string& text) {
  if (text == "rich") return 1.0;
  if (text == "medium") return 0.5;
  if (text == "poor") return 0.08;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || v < 0 || v > 1)
    throw Error("texture density must be rich, medium, poor or a number in [0, 1], got '" + text +
                "'");
  return v;
}

}  // namespace alvio::sim
