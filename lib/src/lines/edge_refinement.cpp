#include "alvio/lines/edge_refinement.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace alvio {

namespace {
// Bilinear intensity; the caller keeps p at least one pixel inside the image.
double intensityAt(const cv::Mat& image, const Eigen::Vector2d& p) {
  const int x = static_cast<int>(std::floor(p.x())), y = static_cast<int>(std::floor(p.y()));
  const double fx = p.x() - x, fy = p.y() - y;
  const uchar* r0 = image.ptr<uchar>(y) + x;
  const uchar* r1 = image.ptr<uchar>(y + 1) + x;
  return (1 - fy) * ((1 - fx) * r0[0] + fx * r0[1]) + fy * ((1 - fx) * r1[0] + fx * r1[1]);
}

constexpr double kStepPx = 0.5;  // profile sampling across the line
constexpr int kMaxProfile = 32;
}  // namespace

bool refineSegmentToEdge(const cv::Mat& image, const EdgeRefinementOptions& options,
                         LineSegment* segment) {
  const double length = segment->length();
  if (image.type() != CV_8UC1 || length < 2 * options.sample_spacing_px) return false;
  const Eigen::Vector2d dir = segment->direction();
  const Eigen::Vector2d normal(-dir.y(), dir.x());
  // Derivatives at offsets -search .. +search across the line, from intensities half a step
  // beyond them on either side.
  const int half = static_cast<int>(std::round(options.search_px / kStepPx));
  const int n_deriv = 2 * half + 1;
  if (n_deriv + 1 > kMaxProfile) return false;
  const double reach = options.search_px + kStepPx;
  const int samples =
      std::clamp(static_cast<int>(length / options.sample_spacing_px), 2, options.max_samples);

  std::vector<Eigen::Vector2d> base;
  std::vector<double> derivs;  // n_deriv per sample in base
  base.reserve(samples);
  derivs.reserve(std::size_t(samples) * n_deriv);
  double polarity_sum = 0;
  for (int s = 0; s < samples; ++s) {
    const Eigen::Vector2d p = segment->pointAt(length * (s + 0.5) / samples);
    const Eigen::Vector2d lo = p - reach * normal, hi = p + reach * normal;
    if (std::min({lo.x(), lo.y(), hi.x(), hi.y()}) < 0 ||
        std::max(lo.x(), hi.x()) > image.cols - 2 || std::max(lo.y(), hi.y()) > image.rows - 2)
      continue;
    double intensity[kMaxProfile];
    for (int k = 0; k <= n_deriv; ++k)
      intensity[k] = intensityAt(image, p + ((k - half - 0.5) * kStepPx) * normal);
    for (int k = 0; k < n_deriv; ++k) derivs.push_back((intensity[k + 1] - intensity[k]) / kStepPx);
    polarity_sum += derivs[derivs.size() - n_deriv + half];
    base.push_back(p);
  }
  if (base.size() < 3) return false;
  const double polarity = polarity_sum >= 0 ? 1.0 : -1.0;

  std::vector<Eigen::Vector2d> peaks;
  peaks.reserve(base.size());
  for (std::size_t s = 0; s < base.size(); ++s) {
    const double* d = &derivs[s * n_deriv];
    int best = -1;
    for (int k = 1; k + 1 < n_deriv; ++k)
      if (polarity * d[k] >= options.min_contrast &&
          (best < 0 || polarity * d[k] > polarity * d[best]))
        best = k;
    if (best < 0) continue;
    const double a = polarity * d[best - 1], b = polarity * d[best], c = polarity * d[best + 1];
    if (b < a || b < c) continue;  // the strongest inside lies at the window's edge
    const double curvature = a - 2 * b + c;
    const double delta = curvature < 0 ? 0.5 * (a - c) / curvature : 0.0;
    peaks.push_back(base[s] + ((best - half + delta) * kStepPx) * normal);
  }

  // Fit, then drop the worst peak and fit again until every peak is within max_residual_px:
  // one peak on a neighbouring edge must not tilt the line away from all the others.
  const std::size_t needed = std::max<std::size_t>(
      3, static_cast<std::size_t>(std::ceil(options.min_inlier_fraction * samples)));
  LineSegment fit;
  const Eigen::Vector2d reference = segment->end - segment->start;
  while (true) {
    if (peaks.size() < needed || !fitSegmentToPoints(peaks, reference, &fit)) return false;
    std::size_t worst = 0;
    double worst_distance = -1;
    for (std::size_t i = 0; i < peaks.size(); ++i) {
      const double d = fit.distanceToLine(peaks[i]);
      if (d > worst_distance) {
        worst_distance = d;
        worst = i;
      }
    }
    if (worst_distance <= options.max_residual_px) break;
    peaks.erase(peaks.begin() + static_cast<std::ptrdiff_t>(worst));
  }

  // The detector's extent, projected onto the refined line.
  const LineSegment refined(fit.pointAt(fit.positionAlong(segment->start)),
                            fit.pointAt(fit.positionAlong(segment->end)));
  if ((refined.start - segment->start).norm() > options.max_shift_px ||
      (refined.end - segment->end).norm() > options.max_shift_px)
    return false;
  *segment = refined;
  return true;
}

}  // namespace alvio
