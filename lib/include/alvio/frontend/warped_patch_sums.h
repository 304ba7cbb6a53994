#pragma once
// The sums one step of an anchored patch's warped alignment needs (frontend/patch_anchors.h),
// from one pass over the image patch under the warp x' = A x + q. The AVX2 path samples eight
// pixels at a time and adds them in the scalar path's order, so both give the same bits.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "alvio/common/widest_vectors.h"

namespace alvio {

/// n x n samples (n odd) of the 8-bit `image`, bilinear, at A (c - n/2, r - n/2) + (qx, qy)
/// for row r and column c. `packed` holds 8 floats per sample, row by row; sums[i] is the sum
/// over the samples of value x packed[i], and *s2 the sum of the squared values. The caller
/// keeps every sample and the pixel right of and below it inside the image.
void warpedPatchSums(const cv::Mat& image, const Eigen::Matrix2d& A, double qx, double qy, int n,
                     const float* packed, float* s2, float* sums,
                     Vectors vectors = Vectors::kWidest);

}  // namespace alvio
