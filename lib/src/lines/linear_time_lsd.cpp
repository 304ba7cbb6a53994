#include "alvio/lines/linear_time_lsd.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "alvio/common/angles.h"
#include "alvio/common/widest_vectors.h"

namespace alvio {

namespace {
constexpr double kAngleToleranceDeg = 22.5;
constexpr double kTolerance = CV_PI * kAngleToleranceDeg / 180.0;
// Probability that a pixel of noise is aligned within the tolerance.
constexpr double kAlignedProbability = kAngleToleranceDeg / 180.0;
constexpr int kGradientBins = 1024;
constexpr float kNotComputed = std::numeric_limits<float>::quiet_NaN();
}  // namespace

LinearTimeLsd::LinearTimeLsd(double scale, double sigma_scale, double quant, bool pyramid_downscale)
    : scale_(scale), pyramid_downscale_(pyramid_downscale) {
  CV_Assert(scale > 0 && scale <= 1 && sigma_scale > 0);
  setQuant(quant);
  CV_Assert(!pyramid_downscale || scale == 0.5);
  if (scale != 1 && !pyramid_downscale) {
    // The blur that keeps the scaled image free of aliasing: sigma = sigma_scale / scale,
    // truncated where the kernel falls under 10^-3.
    const double sigma = sigma_scale / scale;
    const int h = static_cast<int>(std::ceil(sigma * std::sqrt(2 * 3 * std::log(10.0))));
    blur_.emplace(2 * h + 1, sigma);
  }
  // Most gradients are small: their directions are looked up, computed once by the same calls
  // as the others'.
  direction_table_.resize(kTableSide * kTableSide);
  // The table also holds the seeds' double cosine and sine, which glibc computes slowly.
  for (int gy = -kTableRadius; gy <= kTableRadius; ++gy)
    for (int gx = -kTableRadius; gx <= kTableRadius; ++gx) {
      Direction& d = direction_table_[(gy + kTableRadius) * kTableSide + gx + kTableRadius];
      d = direction(levelLineAngle(gx, gy));
      d.seed = seedCosSin(d.angle);
    }
}

void LinearTimeLsd::setQuant(double quant) {
  CV_Assert(quant > 0);
  threshold_ = quant / std::sin(kTolerance);
}

void LinearTimeLsd::detect(const cv::Mat& gray, std::vector<cv::Vec4f>* segments) {
  CV_Assert(!gray.empty() && gray.type() == CV_8UC1);
  segments->clear();
  // No 2x2 gradient fits into a smaller image.
  if (cvRound(gray.cols * scale_) < 2 || cvRound(gray.rows * scale_) < 2) return;
  // Where a scaled pixel's centre lies in the input image, against resize's 2 u_s + 0.5.
  double centre_shift = 0.0;
  if (pyramid_downscale_) {
    cv::pyrDown(gray, scaled_);
    // pyrDown centres scaled pixel u_s on input pixel 2 u_s.
    centre_shift = -0.5;
  } else if (scale_ != 1) {
    blur_->apply(gray, blurred_);
    cv::resize(blurred_, scaled_, cv::Size(), scale_, scale_, cv::INTER_LINEAR_EXACT);
  } else {
    scaled_ = gray;
  }
  width_ = scaled_.cols;
  height_ = scaled_.rows;
  computeGradient();
  orderSeeds();

  // The smallest region that can be a meaningful (a contrario) event among the image's
  // candidate rectangles.
  const double log_tests =
      5 * (std::log10(double(width_)) + std::log10(double(height_))) / 2 + std::log10(11.0);
  const std::size_t min_region = std::size_t(-log_tests / std::log10(kAlignedProbability));

  for (int seed : seeds_) {
    if (used_[seed]) continue;
    const double region_angle = growRegion(seed);
    if (region_.size() < min_region) continue;
    const cv::Vec4d s = regionToSegment(region_angle);
    // Pixel centres are at +0.5, then back to the input image.
    auto out = [&](double u) { return float((u + 0.5) / scale_ + centre_shift); };
    segments->emplace_back(out(s[0]), out(s[1]), out(s[2]), out(s[3]));
  }
}

LinearTimeLsd::Direction LinearTimeLsd::direction(float angle) {
  // In float, as the region's running sum adds them; the seed's terms left to growRegion.
  return {angle, {std::cos(angle), std::sin(angle)}, {kNotComputed, kNotComputed}};
}

LinearTimeLsd::CosSin LinearTimeLsd::seedCosSin(float angle) {
  const double a = angle;
  return {static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a))};
}

float LinearTimeLsd::levelLineAngle(int gx, int gy) {
  // The level-line direction: the gradient turned by 90 degrees.
  return static_cast<float>(cv::fastAtan2(float(gx), float(-gy)) * kDegToRad);
}

namespace {
// strong[x] = 1 where the 2x2 gradient at (x, row) has a squared norm (times 4) above
// min_norm2, else 0; plain loops, 16 or 32 pixels at a time.
ALVIO_WIDEST_VECTORS void strongGradients(const uint8_t* row, const uint8_t* next, int cols,
                                          int min_norm2, uint8_t* __restrict strong) {
  for (int x = 0; x < cols; ++x) {
    const int diagonal = next[x + 1] - row[x];
    const int antidiagonal = row[x + 1] - next[x];
    const int gx = diagonal + antidiagonal;
    const int gy = diagonal - antidiagonal;
    strong[x] = gx * gx + gy * gy > min_norm2;
  }
}
}  // namespace

void LinearTimeLsd::computeGradient() {
  const std::size_t n = std::size_t(width_) * height_;
  // Pixels without a direction can join no region: marked used, growRegion skips them in the
  // same test as the pixels already taken. The per-pixel values are read only where a
  // direction is, so they need no clearing.
  used_.assign(n, 1);
  angle_.resize(n);
  gradient_.resize(n);
  cos_sin_.resize(n);
  seed_cos_sin_.resize(n);
  candidates_.resize(n);
  strong_.resize(width_);
  std::size_t count = 0;
  max_gradient_ = 0.0f;
  // Only pixels above the threshold need a square root, and a direction. Which ones are is
  // found for a whole row first, then they are listed without a branch per pixel (a fifth of
  // them pass, in no pattern a branch predictor could learn). An integer squared norm is
  // above the threshold exactly when it is above the threshold's integer part.
  const int min_norm2 = static_cast<int>(std::floor(4.0 * threshold_ * threshold_));
  for (int y = 0; y + 1 < height_; ++y) {
    const uint8_t* row = scaled_.ptr<uint8_t>(y);
    const uint8_t* next = scaled_.ptr<uint8_t>(y + 1);
    const int offset = y * width_;
    strongGradients(row, next, width_ - 1, min_norm2, strong_.data());
    const std::size_t first = count;
    for (int x = 0; x + 1 < width_; ++x) {
      candidates_[count] = offset + x;
      count += strong_[x];
    }
    for (std::size_t i = first; i < count; ++i) {
      const int x = candidates_[i] - offset;
      // 2x2 differences; the gradient belongs to the square's centre, hence the +0.5 above.
      const int diagonal = next[x + 1] - row[x];
      const int antidiagonal = row[x + 1] - next[x];
      const int gx = diagonal + antidiagonal;
      const int gy = diagonal - antidiagonal;
      const int norm2 = gx * gx + gy * gy;
      const float g = static_cast<float>(std::sqrt(norm2 / 4.0));
      gradient_[offset + x] = g;
      max_gradient_ = std::max(max_gradient_, g);
      const Direction d =
          std::abs(gx) <= kTableRadius && std::abs(gy) <= kTableRadius
              ? direction_table_[(gy + kTableRadius) * kTableSide + gx + kTableRadius]
              : direction(levelLineAngle(gx, gy));
      angle_[offset + x] = d.angle;
      cos_sin_[offset + x] = d.cos_sin;
      seed_cos_sin_[offset + x] = d.seed;
      used_[offset + x] = 0;
    }
  }
  candidates_.resize(count);
}

void LinearTimeLsd::orderSeeds() {
  seeds_.clear();
  if (max_gradient_ <= 0) return;
  const double bin_per_gradient = double(kGradientBins - 1) / max_gradient_;
  // Counting sort by bin, strongest first: bin_count_[b] becomes the first slot of bin b. The
  // candidates are in raster order, so each bin keeps it.
  bin_count_.assign(kGradientBins + 1, 0);
  seed_bin_.resize(candidates_.size());
  for (std::size_t i = 0; i < candidates_.size(); ++i) {
    const float g = gradient_[candidates_[i]];
    seed_bin_[i] = kGradientBins - 1 - std::min(kGradientBins - 1, int(g * bin_per_gradient));
    ++bin_count_[seed_bin_[i] + 1];
  }
  for (int b = 0; b < kGradientBins; ++b) bin_count_[b + 1] += bin_count_[b];
  seeds_.resize(candidates_.size());
  for (std::size_t i = 0; i < candidates_.size(); ++i)
    seeds_[bin_count_[seed_bin_[i]]++] = candidates_[i];
}

double LinearTimeLsd::growRegion(int seed) {
  // Local copies: the byte stores to `used` could alias the members, which the compiler
  // would otherwise load again for every neighbour.
  uint8_t* const used = used_.data();
  const float* const angle = angle_.data();
  const float* const gradient = gradient_.data();
  const CosSin* const cos_sin = cos_sin_.data();
  const int width = width_, height = height_;
  region_.clear();
  used[seed] = 1;
  double region_angle = angle[seed];
  region_.push_back({seed % width, seed / width, angle[seed], gradient[seed]});
  CosSin start = seed_cos_sin_[seed];
  if (std::isnan(start.cos)) start = seedCosSin(angle[seed]);
  float sum_dx = start.cos;
  float sum_dy = start.sin;
  auto visit = [&](int k, int x, int y) {
    if (used[k]) return;
    // Within the tolerance of the region's direction, modulo 2 pi.
    const float a = angle[k];
    double d = std::fabs(region_angle - a);
    if (d > 1.5 * CV_PI) d = std::fabs(d - 2 * CV_PI);
    if (!(d <= kTolerance)) return;
    used[k] = 1;
    region_.push_back({x, y, a, gradient[k]});
    sum_dx += cos_sin[k].cos;
    sum_dy += cos_sin[k].sin;
    region_angle = cv::fastAtan2(sum_dy, sum_dx) * kDegToRad;
  };
  for (std::size_t i = 0; i < region_.size(); ++i) {
    const int cx = region_[i].x, cy = region_[i].y;
    if (cx > 0 && cy > 0 && cx + 1 < width && cy + 1 < height) {
      // The 8 neighbours in raster order (the centre is used), without the image's bounds.
      const int c = cy * width + cx;
      visit(c - width - 1, cx - 1, cy - 1);
      visit(c - width, cx, cy - 1);
      visit(c - width + 1, cx + 1, cy - 1);
      visit(c - 1, cx - 1, cy);
      visit(c + 1, cx + 1, cy);
      visit(c + width - 1, cx - 1, cy + 1);
      visit(c + width, cx, cy + 1);
      visit(c + width + 1, cx + 1, cy + 1);
      continue;
    }
    const int x0 = std::max(cx - 1, 0), x1 = std::min(cx + 1, width - 1);
    const int y0 = std::max(cy - 1, 0), y1 = std::min(cy + 1, height - 1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) visit(y * width + x, x, y);
  }
  return region_angle;
}

cv::Vec4d LinearTimeLsd::regionToSegment(double region_angle) const {
  double cx = 0, cy = 0, weight = 0;
  for (const RegionPixel& p : region_) {
    cx += p.x * double(p.gradient);
    cy += p.y * double(p.gradient);
    weight += p.gradient;
  }
  cx /= weight;
  cy /= weight;

  // The axis of least inertia: the eigenvector of the smaller eigenvalue.
  double ixx = 0, iyy = 0, ixy = 0;
  for (const RegionPixel& p : region_) {
    const double dx = p.x - cx, dy = p.y - cy;
    ixx += dy * dy * p.gradient;
    iyy += dx * dx * p.gradient;
    ixy -= dx * dy * p.gradient;
  }
  const double lambda = 0.5 * (ixx + iyy - std::sqrt((ixx - iyy) * (ixx - iyy) + 4.0 * ixy * ixy));
  double theta = std::fabs(ixx) > std::fabs(iyy) ? cv::fastAtan2(float(lambda - ixx), float(ixy))
                                                 : cv::fastAtan2(float(ixy), float(lambda - iyy));
  theta *= kDegToRad;
  // Orient it as the level lines, so that a segment keeps the side of its brighter region.
  double diff = theta - region_angle;
  while (diff <= -CV_PI) diff += 2 * CV_PI;
  while (diff > CV_PI) diff -= 2 * CV_PI;
  if (std::fabs(diff) > kTolerance) theta += CV_PI;

  const double dx = std::cos(theta), dy = std::sin(theta);
  double l_min = 0, l_max = 0;
  for (const RegionPixel& p : region_) {
    const double l = (p.x - cx) * dx + (p.y - cy) * dy;
    l_min = std::min(l_min, l);
    l_max = std::max(l_max, l);
  }
  return {cx + l_min * dx, cy + l_min * dy, cx + l_max * dx, cy + l_max * dy};
}

}  // namespace alvio
