#include "alvio/frontend/exposure_compensation.h"

#include <algorithm>
#include <cmath>

namespace alvio {

namespace {
// Outside these means a frame is black or saturated: there is nothing to scale, and it must
// not become the reference level either.
constexpr double kMinMean = 4.0, kMaxMean = 251.0;
}  // namespace

const cv::Mat& ExposureCompensation::apply(const cv::Mat& gray, double mean, cv::Mat* buffer) {
  last_gain_ = 1.0;
  if (threshold_ <= 0 || mean < kMinMean || mean > kMaxMean) {
    level_ = 0;
    return gray;
  }
  if (level_ <= 0 || std::abs(level_ / mean - 1.0) <= threshold_) {
    level_ = mean;
    return gray;
  }
  last_gain_ = std::clamp(level_ / mean, 1.0 / max_gain_, max_gain_);
  gray.convertTo(*buffer, CV_8U, last_gain_);  // saturates
  return *buffer;
}

}  // namespace alvio
