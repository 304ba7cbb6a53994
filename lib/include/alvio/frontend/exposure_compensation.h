#pragma once
// KLT assumes that a pixel keeps its brightness from one frame to the next. A sudden global
// change (an auto-exposure step, lights switched, flicker) breaks that for every feature at
// once, and the tracks are lost together. A frame whose mean brightness jumped by more than
// a threshold is scaled back to the level the trackers saw last; slow changes pass as they
// are, so nothing accumulates while the light drifts.

#include <opencv2/core.hpp>

namespace alvio {

class ExposureCompensation {
 public:
  /// `threshold`: relative jump of the mean brightness that is compensated (<= 0: off).
  explicit ExposureCompensation(double threshold, double max_gain = 8.0)
      : threshold_(threshold), max_gain_(max_gain) {}

  /// The image the trackers should see: `gray` itself, or a scaled copy in `*buffer`.
  /// `mean` is the mean brightness of `gray`.
  const cv::Mat& apply(const cv::Mat& gray, double mean, cv::Mat* buffer);

  /// The gain applied to the last image (1 when it passed as it was).
  double lastGain() const { return last_gain_; }

 private:
  double threshold_, max_gain_;
  double level_ = 0;  ///< mean brightness of the last image the trackers saw (0: none yet)
  double last_gain_ = 1;
};

}  // namespace alvio
