#pragma once
// Shi-Tomasi corners, as cv::goodFeaturesToTrack picks them (same rules, same order, ties
// included), but faster: the response is summed in exact integers (MinEigenResponse), its
// local maxima are found in one pass over the mask, and the candidates are not all sorted:
// on textured images nearly every pixel passes the 1 % quality level, and OpenCV sorts tens
// of thousands of local maxima to keep the few dozen a frame needs. Here they are ranked a
// block at a time, strongest first, until enough corners are found. Buffers are kept
// between frames.

#include <opencv2/core.hpp>
#include <vector>

#include "alvio/frontend/min_eigen_response.h"

namespace alvio {

class CornerDetector {
 public:
  /// Up to `max_corners` (> 0) corners of the 8-bit image where `mask` (8-bit, or empty) is
  /// non-zero, each at least `min_distance` px from the ones before it, strongest first.
  /// The result is cv::goodFeaturesToTrack(image, corners, max_corners, quality_level,
  /// min_distance, mask) with its default 3x3 block and aperture, except where OpenCV's
  /// float rounding of the response (relative 3e-5) reorders two nearly equal candidates.
  std::vector<cv::Point2f> detect(const cv::Mat& image, int max_corners, double quality_level,
                                  double min_distance, const cv::Mat& mask = cv::Mat());

 private:
  struct Candidate {
    float response;
    int index;  ///< y * width + x: OpenCV breaks ties by address, the later pixel first
  };
  MinEigenResponse response_calculator_;
  cv::Mat response_;
  std::vector<float> column_max_;      // one row's maximum over three rows, per column
  std::vector<Candidate> candidates_;  // room for every inner pixel; the first few in use
  std::vector<std::vector<cv::Point2f>> grid_;
};

}  // namespace alvio
