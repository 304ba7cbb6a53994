#pragma once
// A tracker's KLT pyramids from one frame to the next. Each frame's pyramid is built into the
// buffers of the one from two frames back: by then nothing else holds them, and refilling
// them spares a page fault per touched page of a fresh allocation.

#include <opencv2/core.hpp>
#include <vector>

#include "alvio/frontend/optical_flow_pyramid.h"

namespace alvio {

class PyramidHistory {
 public:
  /// This frame's pyramid of `image` (buildOpticalFlowPyramid8u), valid until advance().
  /// Never built into the caller's image, which may change after the tracker returns.
  const std::vector<cv::Mat>& build(const cv::Mat& image, cv::Size window, int max_level) {
    current_.swap(spare_);
    spare_.clear();
    buildOpticalFlowPyramid8u(image, window, max_level, &current_);
    return current_;
  }

  /// The previous frame's pyramid: empty on the first frame and after forgetPrevious().
  const std::vector<cv::Mat>& previous() const { return previous_; }

  /// This frame's pyramid becomes the previous one; the previous one's buffers are kept for
  /// the next frame to fill.
  void advance() {
    spare_.swap(previous_);
    previous_.swap(current_);
    current_.clear();
  }

  /// The next frame has no previous pyramid to track from (a reset).
  void forgetPrevious() { previous_.clear(); }

 private:
  std::vector<cv::Mat> previous_, current_, spare_;
};

}  // namespace alvio
