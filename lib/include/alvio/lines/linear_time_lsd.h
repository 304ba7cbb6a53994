#pragma once
// LSD, the Line Segment Detector of von Gioi et al. (IPOL 2012), without refinement: the steps
// and constants of OpenCV's cv::LineSegmentDetector with LSD_REFINE_NONE (Gaussian blur and
// scaling, 2x2 gradient, region growing at 22.5 deg, rectangle by the region's inertia), but
// seeds ordered as the paper orders them.
//
// OpenCV 4.6 puts every pixel of the scaled image into one list and std::sorts it by gradient
// (about 90 000 entries on a EuRoC frame at scale 0.5), which is most of its time. Here only
// the pixels that can start a region (gradient above the threshold, a fifth of them) are
// ordered, by a counting sort over the same 1024 bins, in raster order within a bin. Seeds in
// one bin may therefore be tried in another order than OpenCV's, so a few segments differ;
// test_line_detector compares the two.

#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "alvio/frontend/gaussian_blur_8u.h"

namespace alvio {

class LinearTimeLsd {
 public:
  /// `scale` and `sigma_scale` as OpenCV's (sigma = sigma_scale / scale when scale < 1);
  /// `quant` bounds the gradient's quantisation error (threshold quant / sin(22.5 deg)).
  /// `pyramid_downscale` (scale 0.5 only): halve the image with cv::pyrDown's 5-tap Gaussian
  /// instead of the sigma_scale blur and a resize, several times cheaper (docs/benchmarks.md).
  LinearTimeLsd(double scale, double sigma_scale, double quant, bool pyramid_downscale = false);

  /// Segments (x1, y1, x2, y2) in the input image's pixels, in OpenCV's convention: a scaled
  /// image coordinate u_s comes back as (u_s + 0.5) / scale, whichever way the image was scaled.
  /// `gray` is CV_8UC1.
  void detect(const cv::Mat& gray, std::vector<cv::Vec4f>* segments);

  /// Changes `quant` for the next detect() (the threshold is quant / sin(22.5 deg)).
  void setQuant(double quant);

 private:
  struct RegionPixel {
    int x, y;
    float angle, gradient;
  };

  struct CosSin {
    float cos, sin;
  };
  struct Direction {
    float angle;
    CosSin cos_sin;
    CosSin seed;  ///< the cosine and sine in double, rounded to float: a region's first term
  };

  /// The level-line angle [rad] of the 2x2 gradient (gx, gy): the gradient turned by 90 deg.
  static float levelLineAngle(int gx, int gy);
  /// The angle with its cosine and sine in float, as region growth sums them; `seed` NaN
  /// (filled in the direction table only).
  static Direction direction(float angle);
  /// The cosine and sine in double, rounded to float, as a region starts from its seed's.
  static CosSin seedCosSin(float angle);
  void computeGradient();
  void orderSeeds();
  /// Grows the region of pixels aligned with the seed's running mean direction (8-connected).
  /// Returns that mean direction [rad].
  double growRegion(int seed);
  /// The region's rectangle: its gradient-weighted centre, its axis of least inertia, and the
  /// extreme projections on that axis, as a segment in scaled-image pixels.
  cv::Vec4d regionToSegment(double region_angle) const;

  double scale_, threshold_;
  bool pyramid_downscale_;
  std::optional<GaussianBlur8u> blur_;  // OpenCV's blur before the scaling, bit for bit
  cv::Mat blurred_, scaled_;
  int width_ = 0, height_ = 0;
  // Per pixel, defined where used_ is 0 after computeGradient.
  std::vector<float> angle_;     // level-line direction [rad]
  std::vector<float> gradient_;  // gradient norm
  std::vector<uint8_t> used_;    // taken by a region, or without a direction
  std::vector<int> candidates_;  // pixels with a direction, in raster order
  std::vector<uint8_t> strong_;  // one row's: 1 where the gradient is above the threshold
  std::vector<int> seed_bin_;    // each candidate's gradient bin
  float max_gradient_ = 0.0f;
  static constexpr int kTableRadius = 63, kTableSide = 2 * kTableRadius + 1;
  std::vector<Direction> direction_table_;  // for |gx|, |gy| <= kTableRadius
  std::vector<CosSin> cos_sin_;             // of angle_
  // Direction::seed of angle_, from the table; NaN where the gradient lies outside it (only
  // the pixels that start a region need it, and glibc's double sincos is slow).
  std::vector<CosSin> seed_cos_sin_;
  std::vector<int> seeds_;  // pixel indices, strongest gradient bin first
  std::vector<int> bin_count_;
  std::vector<RegionPixel> region_;
};

}  // namespace alvio
