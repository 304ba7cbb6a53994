#pragma once
// Shi-Tomasi corners, exactly as cv::goodFeaturesToTrack picks them (same responses, same
// order, ties included), but without sorting every candidate: on textured images nearly
// every pixel passes the 1 % quality level, and OpenCV sorts tens of thousands of local
// maxima to keep the few dozen a frame needs. Here they are ranked a block at a time,
// strongest first, until enough corners are found. Buffers are kept between frames.

#include <opencv2/core.hpp>
#include <vector>

namespace alvio {

class CornerDetector {
 public:
  /// Up to `max_corners` (> 0) corners of the 8-bit image where `mask` (8-bit, or empty) is
  /// non-zero, each at least `min_distance` px from the ones before it, strongest first.
  /// The result equals cv::goodFeaturesToTrack(image, corners, max_corners, quality_level,
  /// min_distance, mask) with its default 3x3 block and aperture.
  std::vector<cv::Point2f> detect(const cv::Mat& image, int max_corners, double quality_level,
                                  double min_distance, const cv::Mat& mask = cv::Mat());

 private:
  struct Candidate {
    float response;
    int index;  ///< y * width + x: OpenCV breaks ties by address, the later pixel first
  };
  cv::Mat response_, dilated_, is_candidate_, nonzero_;
  std::vector<cv::Point> locations_;
  std::vector<Candidate> candidates_;
  std::vector<std::vector<cv::Point2f>> grid_;
};

}  // namespace alvio
