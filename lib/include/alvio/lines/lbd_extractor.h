#pragma once
// LBD binary descriptors (OpenCV contrib line_descriptor::BinaryDescriptor, 256 bits) for
// segments from any detector: the segments are wrapped as single-octave KeyLines.

#include <opencv2/core.hpp>
#include <opencv2/line_descriptor.hpp>
#include <vector>

#include "alvio/lines/line_segment.h"

namespace alvio {

class LbdExtractor {
 public:
  LbdExtractor();
  /// One 32-byte row (CV_8U) per segment, in the segments' order; empty for no segments.
  cv::Mat compute(const cv::Mat& gray, const std::vector<LineSegment>& segments) const;

 private:
  cv::Ptr<cv::line_descriptor::BinaryDescriptor> descriptor_;
};

}  // namespace alvio
