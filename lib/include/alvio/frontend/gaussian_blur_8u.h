#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace alvio {

/// cv::GaussianBlur of an 8-bit single-channel image with OpenCV's default border (reflect
/// 101), bit for bit (views into larger images and images smaller than the kernel go to
/// OpenCV), in about a third of OpenCV 4.6's time. OpenCV blurs 8-bit images in
/// exact fixed point: integer weights summing to 256 per direction and one rounding at the
/// end. Every order of the same integer sums gives the same bytes, so here the sums run 16
/// pixels at a time in 16-bit lanes, which OpenCV's own code does not manage.
///
/// The weights are read from OpenCV once, from its blur of a vertical line, so whatever
/// OpenCV build is linked sets them. Where they cannot be read exactly, or the kernel is wider
/// than handled here, `apply` calls cv::GaussianBlur.
class GaussianBlur8u {
 public:
  static constexpr int kMaxRadius = 6;  ///< nonzero weights at most this far from the centre

  GaussianBlur8u(int ksize, double sigma);

  /// `dst` = cv::GaussianBlur(src, ksize x ksize, sigma); `src` must be CV_8UC1.
  void apply(const cv::Mat& src, cv::Mat& dst);

  /// True when `apply` runs alvio's code, false when it calls OpenCV.
  bool ownCode() const { return radius_ > 0; }
  /// The weights read from OpenCV (8 fractional bits), centre last; empty without ownCode().
  const std::vector<std::uint16_t>& halfKernel() const { return half_kernel_; }

 private:
  int ksize_;
  double sigma_;
  int radius_ = 0;                          ///< of the nonzero weights; 0: OpenCV blurs
  std::vector<std::uint16_t> half_kernel_;  ///< weights radius_ .. 1 away, then the centre
  // One row's vertical sums, split into high and low bytes and padded by radius_ each side.
  std::vector<std::uint8_t> high_, low_;
  std::vector<const std::uint8_t*> rows_;
};

}  // namespace alvio
