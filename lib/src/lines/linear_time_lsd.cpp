#include "alvio/lines/linear_time_lsd.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace alvio {

namespace {
constexpr double kAngleToleranceDeg = 22.5;
constexpr double kTolerance = CV_PI * kAngleToleranceDeg / 180.0;
// Probability that a pixel of noise is aligned within the tolerance.
constexpr double kAlignedProbability = kAngleToleranceDeg / 180.0;
constexpr int kGradientBins = 1024;
constexpr float kUndefined = -1024.0f;
constexpr double kDegToRad = CV_PI / 180.0;
}  // namespace

LinearTimeLsd::LinearTimeLsd(double scale, double sigma_scale, double quant, bool pyramid_downscale)
    : scale_(scale),
      sigma_scale_(sigma_scale),
      threshold_(quant / std::sin(kTolerance)),
      pyramid_downscale_(pyramid_downscale) {
  CV_Assert(scale > 0 && scale <= 1 && sigma_scale > 0 && quant > 0);
  CV_Assert(!pyramid_downscale || scale == 0.5);
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
    // The blur that keeps the scaled image free of aliasing: sigma = sigma_scale / scale,
    // truncated where the kernel falls under 10^-3.
    const double sigma = sigma_scale_ / scale_;
    const int h = static_cast<int>(std::ceil(sigma * std::sqrt(2 * 3 * std::log(10.0))));
    cv::GaussianBlur(gray, blurred_, cv::Size(2 * h + 1, 2 * h + 1), sigma);
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

  used_.assign(angle_.size(), 0);
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

void LinearTimeLsd::computeGradient() {
  const std::size_t n = std::size_t(width_) * height_;
  angle_.assign(n, kUndefined);
  gradient_.assign(n, 0.0f);
  // Compared squared, so that only pixels above the threshold need a square root.
  const double min_norm2 = 4.0 * threshold_ * threshold_;
  for (int y = 0; y + 1 < height_; ++y) {
    const uint8_t* row = scaled_.ptr<uint8_t>(y);
    const uint8_t* next = scaled_.ptr<uint8_t>(y + 1);
    float* angle = &angle_[std::size_t(y) * width_];
    float* gradient = &gradient_[std::size_t(y) * width_];
    for (int x = 0; x + 1 < width_; ++x) {
      // 2x2 differences; the gradient belongs to the square's centre, hence the +0.5 above.
      const int diagonal = next[x + 1] - row[x];
      const int antidiagonal = row[x + 1] - next[x];
      const int gx = diagonal + antidiagonal;
      const int gy = diagonal - antidiagonal;
      const int norm2 = gx * gx + gy * gy;
      if (norm2 <= min_norm2) continue;
      gradient[x] = static_cast<float>(std::sqrt(norm2 / 4.0));
      // The level-line direction: the gradient turned by 90 degrees.
      angle[x] = static_cast<float>(cv::fastAtan2(float(gx), float(-gy)) * kDegToRad);
    }
  }
}

void LinearTimeLsd::orderSeeds() {
  float max_gradient = 0;
  for (float g : gradient_) max_gradient = std::max(max_gradient, g);
  seeds_.clear();
  if (max_gradient <= 0) return;
  const double bin_per_gradient = double(kGradientBins - 1) / max_gradient;
  // Counting sort by bin, strongest first: bin_count_[b] becomes the first slot of bin b.
  bin_count_.assign(kGradientBins + 1, 0);
  auto binOf = [&](float g) {
    return kGradientBins - 1 - std::min(kGradientBins - 1, int(g * bin_per_gradient));
  };
  std::size_t candidates = 0;
  for (std::size_t i = 0; i < angle_.size(); ++i)
    if (angle_[i] != kUndefined) {
      ++bin_count_[binOf(gradient_[i]) + 1];
      ++candidates;
    }
  for (int b = 0; b < kGradientBins; ++b) bin_count_[b + 1] += bin_count_[b];
  seeds_.resize(candidates);
  for (std::size_t i = 0; i < angle_.size(); ++i)
    if (angle_[i] != kUndefined) seeds_[bin_count_[binOf(gradient_[i])]++] = static_cast<int>(i);
}

bool LinearTimeLsd::aligned(int index, double angle) const {
  const float a = angle_[index];
  if (a == kUndefined) return false;
  double d = std::fabs(angle - a);
  if (d > 1.5 * CV_PI) d = std::fabs(d - 2 * CV_PI);
  return d <= kTolerance;
}

double LinearTimeLsd::growRegion(int seed) {
  region_.clear();
  used_[seed] = 1;
  double region_angle = angle_[seed];
  region_.push_back({seed % width_, seed / width_, angle_[seed], gradient_[seed]});
  float sum_dx = static_cast<float>(std::cos(region_angle));
  float sum_dy = static_cast<float>(std::sin(region_angle));
  for (std::size_t i = 0; i < region_.size(); ++i) {
    const int cx = region_[i].x, cy = region_[i].y;
    const int x0 = std::max(cx - 1, 0), x1 = std::min(cx + 1, width_ - 1);
    const int y0 = std::max(cy - 1, 0), y1 = std::min(cy + 1, height_ - 1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const int k = y * width_ + x;
        if (used_[k] || !aligned(k, region_angle)) continue;
        used_[k] = 1;
        region_.push_back({x, y, angle_[k], gradient_[k]});
        sum_dx += std::cos(angle_[k]);
        sum_dy += std::sin(angle_[k]);
        region_angle = cv::fastAtan2(sum_dy, sum_dx) * kDegToRad;
      }
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
