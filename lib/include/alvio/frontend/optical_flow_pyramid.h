#pragma once
// The KLT image pyramid with gradients, as alvio's trackers build it, bit for bit
// cv::buildOpticalFlowPyramid's and faster. OpenCV computes each level's Scharr gradients with
// 128-bit vectors into the level's centre and then copies the whole level again to add their
// border. Here the gradients are computed with the widest vectors the CPU has (chosen when the
// library loads) and only the border is written afterwards, zeroed. Integer arithmetic
// throughout, so the result does not depend on the instructions used.

#include <opencv2/core.hpp>
#include <vector>

namespace alvio {

/// Same result as cv::buildOpticalFlowPyramid(image, *pyramid, window, max_level, true,
/// cv::BORDER_REFLECT_101, cv::BORDER_CONSTANT, false) for an 8-bit one-channel image: levels
/// 0..L (L <= max_level, fewer where a level would be no larger than the window) as
/// image/gradient pairs, each a view into a buffer with a border of the window's size. Returns
/// L. Other image types go to OpenCV. `pyramid` may hold an older pyramid built here for the
/// same image size and window: its buffers are then filled again, where nothing else holds
/// them, instead of new ones being allocated (and faulted in page by page).
int buildOpticalFlowPyramid8u(const cv::Mat& image, cv::Size window, int max_level,
                              std::vector<cv::Mat>* pyramid);

/// The Scharr gradients of one image, as OpenCV's KLT computes them: CV_16SC2 (dx, dy) per
/// pixel, reflect-101 at the edges, into `gradients` (the image's size; its own border is
/// left alone). Exposed for tests.
void scharrGradients(const cv::Mat& image, cv::Mat& gradients);

}  // namespace alvio
