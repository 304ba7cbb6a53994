#include "test_images.h"

#include <opencv2/imgproc.hpp>

namespace alvio::test {

cv::Mat blurredNoise(cv::Size size, uint64_t seed, double sigma) {
  cv::Mat image(size, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  if (sigma > 0) cv::GaussianBlur(image, image, cv::Size(0, 0), sigma);
  return image;
}

cv::Mat stretched(const cv::Mat& image, double lo, double hi) {
  cv::Mat out;
  cv::normalize(image, out, lo, hi, cv::NORM_MINMAX);
  return out;
}

}  // namespace alvio::test
