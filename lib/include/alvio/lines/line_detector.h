#pragma once
// Line segment detection, LSD (linear_time_lsd.h, or OpenCV's cv::LineSegmentDetector) or FLD
// (ximgproc), with a minimum length and a cap on the count (the longest are kept). The detector is
// built once and reused for every frame.

#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc/fast_line_detector.hpp>
#include <vector>

#include "alvio/lines/line_segment.h"
#include "alvio/lines/line_tracker_options.h"
#include "alvio/lines/linear_time_lsd.h"

namespace alvio {

class LineDetector {
 public:
  LineDetector(const LineDetectorOptions& options, cv::Size image_size);

  /// Segments at least shortestLength() long, the longest max_detections of them, longest
  /// first. With a `valid_mask` (CV_8U, non-zero = valid), segments whose endpoints or midpoint
  /// are within the border margin of an invalid pixel are dropped.
  std::vector<LineSegment> detect(const cv::Mat& gray, const cv::Mat& valid_mask = cv::Mat());

  /// Minimum length of a new line [px].
  double minLength() const { return min_length_; }
  /// Minimum length of any returned segment (continuations, pieces of split lines) [px].
  double shortestLength() const { return min_length_ * options_.continuation_length_factor; }
  const LineDetectorOptions& options() const { return options_; }
  /// LSD's quant in the last detect() (lsd_quant unless lsd_reference_brightness lowered it).
  double lastQuant() const { return last_quant_; }

 private:
  /// lsd_quant scaled for the frame's mean brightness (lsd_reference_brightness).
  double quantFor(const cv::Mat& gray, const cv::Mat& valid_mask) const;
  cv::Ptr<cv::LineSegmentDetector> makeOpenCvLsd(double quant) const;

  LineDetectorOptions options_;
  double min_length_;
  double last_quant_;
  std::unique_ptr<LinearTimeLsd> lsd_;
  cv::Ptr<cv::LineSegmentDetector> opencv_lsd_;
  cv::Ptr<cv::ximgproc::FastLineDetector> fld_;
  cv::Mat scaled_;       // FLD's resized input, reused
  cv::Mat source_mask_;  // the valid mask last seen (compared by data pointer)
  cv::Mat eroded_mask_;  // it shrunk by the border margin; empty if it is all valid
};

}  // namespace alvio
