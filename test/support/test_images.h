#pragma once
// Synthetic test images: blurred noise has texture at every scale above the blur, so corner
// detection and KLT find something everywhere in it.

#include <opencv2/core.hpp>

#include <cstdint>

namespace alvio::test {

/// 8-bit uniform noise in [0, 255] from cv::RNG(seed), blurred by a Gaussian of `sigma` px
/// (no blur when sigma <= 0).
cv::Mat blurredNoise(cv::Size size, uint64_t seed, double sigma);

/// `image` with its grey levels stretched linearly to span [lo, hi] (same type).
cv::Mat stretched(const cv::Mat& image, double lo = 0, double hi = 255);

}  // namespace alvio::test
