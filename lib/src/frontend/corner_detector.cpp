#include "alvio/frontend/corner_detector.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>

namespace alvio {

namespace {
// Ranking blocks: enough for a typical frame's corners in one block, small enough that
// ranking it costs little next to the response image.
constexpr std::ptrdiff_t kBlock = 2048;
}  // namespace

std::vector<cv::Point2f> CornerDetector::detect(const cv::Mat& image, int max_corners,
                                                double quality_level, double min_distance,
                                                const cv::Mat& mask) {
  CV_Assert(image.type() == CV_8UC1 && max_corners > 0 && quality_level > 0 && min_distance >= 0);
  CV_Assert(mask.empty() || (mask.type() == CV_8UC1 && mask.size() == image.size()));
  // The response map, thresholded and dilated as OpenCV does: a candidate is a non-zero
  // local maximum of its 3x3 neighbourhood.
  cv::cornerMinEigenVal(image, response_, 3, 3);
  double max_response = 0;
  cv::minMaxLoc(response_, nullptr, &max_response, nullptr, nullptr, mask);
  cv::threshold(response_, response_, max_response * quality_level, 0, cv::THRESH_TOZERO);
  cv::dilate(response_, dilated_, cv::Mat());

  // Candidates: non-zero local maxima inside the mask, one pixel away from the border, in
  // raster order (vectorised comparisons, then one pass over the survivors).
  const int w = image.cols, h = image.rows;
  candidates_.clear();
  if (w > 2 && h > 2) {
    const cv::Rect inner(1, 1, w - 2, h - 2);
    cv::compare(response_(inner), dilated_(inner), is_candidate_, cv::CMP_EQ);
    cv::compare(response_(inner), 0, nonzero_, cv::CMP_GT);  // thresholded: never negative
    cv::bitwise_and(is_candidate_, nonzero_, is_candidate_);
    if (!mask.empty()) cv::bitwise_and(is_candidate_, mask(inner), is_candidate_);
    cv::findNonZero(is_candidate_, locations_);
    for (const cv::Point& p : locations_) {
      const int x = p.x + 1, y = p.y + 1;
      candidates_.push_back({response_.at<float>(y, x), y * w + x});
    }
  }
  const auto stronger = [](const Candidate& a, const Candidate& b) {
    return a.response > b.response || (a.response == b.response && a.index > b.index);
  };

  // OpenCV's spacing test: a grid of min_distance cells, the 3x3 cells around a candidate
  // searched with a float distance against the squared (double) limit.
  const bool spaced = min_distance >= 1;
  const int cell = spaced ? cvRound(min_distance) : 1;
  const int grid_w = (w + cell - 1) / cell, grid_h = (h + cell - 1) / cell;
  if (spaced) {
    grid_.resize(static_cast<std::size_t>(grid_w) * grid_h);
    for (auto& c : grid_) c.clear();
  }
  const double min_distance2 = min_distance * min_distance;
  auto farEnough = [&](int x, int y) {
    const int cx = x / cell, cy = y / cell;
    for (int gy = std::max(0, cy - 1); gy <= std::min(grid_h - 1, cy + 1); ++gy)
      for (int gx = std::max(0, cx - 1); gx <= std::min(grid_w - 1, cx + 1); ++gx)
        for (const cv::Point2f& p : grid_[gy * grid_w + gx]) {
          const float dx = x - p.x, dy = y - p.y;
          if (dx * dx + dy * dy < min_distance2) return false;
        }
    return true;
  };

  std::vector<cv::Point2f> corners;
  auto begin = candidates_.begin();
  while (begin != candidates_.end() && static_cast<int>(corners.size()) < max_corners) {
    const std::ptrdiff_t block = std::min<std::ptrdiff_t>(kBlock, candidates_.end() - begin);
    const auto block_end = begin + block;
    if (block_end != candidates_.end())
      std::nth_element(begin, block_end, candidates_.end(), stronger);
    std::sort(begin, block_end, stronger);
    for (auto it = begin; it != block_end && static_cast<int>(corners.size()) < max_corners; ++it) {
      const int x = it->index % w, y = it->index / w;
      if (spaced && !farEnough(x, y)) continue;
      const cv::Point2f p(static_cast<float>(x), static_cast<float>(y));
      if (spaced) grid_[(y / cell) * grid_w + x / cell].push_back(p);
      corners.push_back(p);
    }
    begin = block_end;
  }
  return corners;
}

}  // namespace alvio
