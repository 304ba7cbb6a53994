#pragma once
// cv::calcOpticalFlowPyrLK for pyramids built by cv::buildOpticalFlowPyramid with their
// gradients (withDerivatives = true), as alvio's trackers build them. It does OpenCV 4.6's
// arithmetic in OpenCV's order, so its tracks are the same bit for bit, and it runs faster.
// OpenCV's SSE2 code handles eight window pixels at a time and finishes each row's remainder
// (5 of 21 pixels, 7 of 15) one pixel at a time: two integer interpolations per pixel and
// iteration. Here every pixel is interpolated eight at a time (sixteen with AVX2, where the
// CPU has it), and only the float sums, whose order fixes the result, go one by one. Other
// pyramids, other builds (no SSE2) and windows narrower than 8 pixels go to OpenCV itself. Bit for
// bit means against an OpenCV whose x86 baseline has no FMA (Debian's is SSE2); one built for FMA
// fuses some of those sums.

#include <opencv2/core.hpp>
#include <vector>

#include "alvio/common/widest_vectors.h"

namespace alvio {

/// Same arguments and results as cv::calcOpticalFlowPyrLK(from_pyramid, to_pyramid, from, *to,
/// *status, cv::noArray(), window, max_level, stop, use_initial_flow ?
/// cv::OPTFLOW_USE_INITIAL_FLOW : 0), with OpenCV's default minimum eigenvalue (1e-4). `to`
/// holds the initial guesses when `use_initial_flow` is set. No per-point error: nothing reads
/// it, and in OpenCV it costs about a tenth of the tracking. `vectors` is for tests and
/// benchmarks of the narrower code.
void trackPyramidalKlt(const std::vector<cv::Mat>& from_pyramid,
                       const std::vector<cv::Mat>& to_pyramid, const std::vector<cv::Point2f>& from,
                       std::vector<cv::Point2f>* to, std::vector<uchar>* status, cv::Size window,
                       int max_level, const cv::TermCriteria& stop, bool use_initial_flow,
                       Vectors vectors = Vectors::kWidest);

}  // namespace alvio
