#pragma once
// The Shi-Tomasi response of cv::cornerMinEigenVal(image, response, 3, 3): the smaller
// eigenvalue of the 3x3-summed structure tensor of 3x3 Sobel derivatives, with the same
// scale and reflect-101 borders. The derivatives, their products and sums are exact
// integers here and only the eigenvalue is rounded, in SIMD-friendly row passes: 0.35x
// OpenCV's time on a 752x480 frame. OpenCV sums floats, so the two differ by its rounding
// (relative 3e-5 at the strongest corners; docs/benchmarks.md).

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace alvio {

class MinEigenResponse {
 public:
  /// `response` becomes a CV_32F image of `image`'s size (8-bit, one channel). Images under
  /// 3x3 pixels go to OpenCV.
  void compute(const cv::Mat& image, cv::Mat* response);

 private:
  void productRow(const cv::Mat& image, int y, int slot);

  // Three image rows' derivative products (xx, xy, yy each), reused as the window slides.
  std::vector<int32_t> products_;
  int product_rows_[3] = {-1, -1, -1};
  // One row at a time, padded by one pixel at each end for the reflected border.
  std::vector<int32_t> smooth_, diff_, sum_xx_, sum_xy_, sum_yy_;
};

}  // namespace alvio
