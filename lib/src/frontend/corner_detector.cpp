#include "alvio/frontend/corner_detector.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <opencv2/core.hpp>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace alvio {

namespace {
// Ranking blocks: enough for a typical frame's corners in one block, small enough that
// ranking it costs little next to the response image.
constexpr std::ptrdiff_t kBlock = 2048;

#if defined(__SSE2__)
// Four mask bytes (the first in the low byte) as four float lanes: all ones where non-zero.
inline __m128 nonZeroLanes(std::uint32_t four) {
  const __m128i zero = _mm_setzero_si128();
  const __m128i bytes = _mm_cvtsi32_si128(static_cast<int>(four));
  const __m128i lanes = _mm_unpacklo_epi16(_mm_unpacklo_epi8(bytes, zero), zero);
  return _mm_castsi128_ps(_mm_cmpgt_epi32(lanes, zero));
}
#endif

// cv::minMaxLoc's maximum inside the mask (0 when the mask is empty of pixels), without its
// search for locations. Four pixels at a time: GCC does not vectorise a float maximum without
// -ffast-math, and this loop was a third of the detector's time. The response has no NaN, so
// the order of the comparisons does not change the result.
double maxInsideMask(const cv::Mat& response, const cv::Mat& mask) {
  constexpr float kLowest = std::numeric_limits<float>::lowest();
  float best = kLowest;
  bool any = mask.empty();
  const int w = response.cols;
  for (int y = 0; y < response.rows; ++y) {
    const float* row = response.ptr<float>(y);
    const uchar* m = mask.empty() ? nullptr : mask.ptr<uchar>(y);
    int x = 0;
#if defined(__SSE2__)
    const __m128 lowest = _mm_set1_ps(kLowest);
    __m128 best4 = lowest;
    for (; x + 4 <= w; x += 4) {
      const __m128 v = _mm_loadu_ps(row + x);
      if (!m) {
        best4 = _mm_max_ps(best4, v);
        continue;
      }
      std::uint32_t four;
      std::memcpy(&four, m + x, 4);
      if (four == 0) continue;  // masked stretches are long: a predictable branch
      any = true;
      const __m128 inside = nonZeroLanes(four);
      best4 = _mm_max_ps(best4, _mm_or_ps(_mm_and_ps(inside, v), _mm_andnot_ps(inside, lowest)));
    }
    float lanes[4];
    _mm_storeu_ps(lanes, best4);
    best = std::max({best, lanes[0], lanes[1], lanes[2], lanes[3]});
#endif
    for (; x < w; ++x) {
      if (m && m[x] == 0) continue;
      any = true;
      best = std::max(best, row[x]);
    }
  }
  return any ? best : 0.0;
}
}  // namespace

std::vector<cv::Point2f> CornerDetector::detect(const cv::Mat& image, int max_corners,
                                                double quality_level, double min_distance,
                                                const cv::Mat& mask) {
  CV_Assert(image.type() == CV_8UC1 && max_corners > 0 && quality_level > 0 && min_distance >= 0);
  CV_Assert(mask.empty() || (mask.type() == CV_8UC1 && mask.size() == image.size()));
  // OpenCV thresholds the response at quality_level times its maximum inside the mask and
  // dilates it; a candidate is a non-zero pixel equal to its dilation, inside the mask and one
  // pixel from the border. That is: above the threshold and above zero, and the largest of its
  // 3x3 block (a thresholded neighbour is zero, weaker by then). One pass over the image
  // instead of five, candidates in the same raster order.
  response_calculator_.compute(image, &response_);
  const double max_response = maxInsideMask(response_, mask);
  const float threshold = static_cast<float>(max_response * quality_level);  // as cv::threshold
  const int w = image.cols, h = image.rows;
  // Branch-free: every inner pixel is written, the next write moves on only past a candidate.
  const std::size_t room = static_cast<std::size_t>(std::max(0, w - 2)) * std::max(0, h - 2);
  if (candidates_.size() < room) candidates_.resize(room);
  column_max_.resize(w);
  float* __restrict column_max = column_max_.data();
  Candidate* out = candidates_.data();
  for (int y = 1; y < h - 1; ++y) {
    const uchar* m = mask.empty() ? nullptr : mask.ptr<uchar>(y);
    const float* __restrict above = response_.ptr<float>(y - 1);
    const float* __restrict row = response_.ptr<float>(y);
    const float* __restrict below = response_.ptr<float>(y + 1);
    for (int x = 0; x < w; ++x) column_max[x] = std::max(std::max(above[x], row[x]), below[x]);
    int x = 1;
#if defined(__SSE2__)
    // Four pixels tested at once; the few that are kept are written one by one, in order.
    const __m128 above_threshold = _mm_set1_ps(std::max(threshold, 0.0f));
    for (; x + 4 <= w - 1; x += 4) {
      std::uint32_t four = 0xffffffffu;
      if (m) {
        std::memcpy(&four, m + x, 4);
        if (four == 0) continue;  // all four masked
      }
      const __m128 v = _mm_loadu_ps(row + x);
      const __m128 block_max =
          _mm_max_ps(_mm_max_ps(_mm_loadu_ps(column_max + x - 1), _mm_loadu_ps(column_max + x)),
                     _mm_loadu_ps(column_max + x + 1));
      const __m128 strongest =
          _mm_and_ps(_mm_cmpgt_ps(v, above_threshold), _mm_cmpge_ps(v, block_max));
      int keep = _mm_movemask_ps(_mm_and_ps(strongest, nonZeroLanes(four)));
      while (keep) {
        const int k = __builtin_ctz(static_cast<unsigned>(keep));
        keep &= keep - 1;
        *out++ = {row[x + k], y * w + x + k};
      }
    }
#endif
    for (; x < w - 1; ++x) {
      const float v = row[x];
      const float block_max =
          std::max(std::max(column_max[x - 1], column_max[x]), column_max[x + 1]);
      const bool keep = (v > threshold) & (v > 0) & (v >= block_max) & (!m || m[x] != 0);
      *out = {v, y * w + x};
      out += keep;
    }
  }
  const auto candidates_end = candidates_.begin() + (out - candidates_.data());
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
  while (begin != candidates_end && static_cast<int>(corners.size()) < max_corners) {
    const std::ptrdiff_t block = std::min<std::ptrdiff_t>(kBlock, candidates_end - begin);
    const auto block_end = begin + block;
    if (block_end != candidates_end) std::nth_element(begin, block_end, candidates_end, stronger);
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
