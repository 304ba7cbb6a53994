#include "alvio/frontend/clahe.h"

#include <algorithm>
#include <cmath>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace alvio {
namespace {
constexpr int kGreyLevels = 256;
}  // namespace

Clahe::Clahe(double clip_limit, int tiles_per_side)
    : clip_limit_(clip_limit),
      tiles_(tiles_per_side),
      fallback_(cv::createCLAHE(clip_limit, cv::Size(tiles_per_side, tiles_per_side))) {}

void Clahe::apply(const cv::Mat& gray, cv::Mat& out) {
  if (gray.type() != CV_8UC1 || gray.cols % tiles_ != 0 || gray.rows % tiles_ != 0 ||
      gray.data == out.data) {
    fallback_->apply(gray, out);
    return;
  }
  if (gray.size() != size_) prepare(gray.size());
  computeTileLuts(gray);
  out.create(gray.size(), CV_8UC1);
  blend(gray, out);
}

void Clahe::prepare(cv::Size size) {
  size_ = size;
  tile_ = cv::Size(size.width / tiles_, size.height / tiles_);
  column_pair_.resize(size.width);
  weight_right_.resize(size.width);
  weight_left_.resize(size.width);
  // cv::CLAHE's tile coordinates and weights, in its float arithmetic.
  const float inverse_tile_width = 1.0f / tile_.width;
  for (int x = 0; x < size.width; ++x) {
    const float tile_x = x * inverse_tile_width - 0.5f;
    const int left = static_cast<int>(std::floor(tile_x));
    weight_right_[x] = tile_x - left;
    weight_left_[x] = 1.0f - weight_right_[x];
    column_pair_[x] = left + 1;
  }
  tile_luts_.resize(static_cast<std::size_t>(tiles_) * tiles_ * kGreyLevels);
  pair_luts_.resize(static_cast<std::size_t>(tiles_) * (tiles_ + 1) * kGreyLevels);
}

void Clahe::computeTileLuts(const cv::Mat& gray) {
  const int area = tile_.area();
  const float scale = static_cast<float>(kGreyLevels - 1) / area;
  const int clip =
      clip_limit_ > 0.0 ? std::max(static_cast<int>(clip_limit_ * area / kGreyLevels), 1) : 0;
  for (int ty = 0; ty < tiles_; ++ty) {
    for (int tx = 0; tx < tiles_; ++tx) {
      // Four interleaved histograms, so consecutive equal pixels do not wait on each other.
      int partial[4][kGreyLevels] = {};
      int histogram[kGreyLevels] = {};
      for (int y = ty * tile_.height; y < (ty + 1) * tile_.height; ++y) {
        const std::uint8_t* row = gray.ptr<std::uint8_t>(y) + tx * tile_.width;
        int x = 0;
        for (; x + 4 <= tile_.width; x += 4) {
          ++partial[0][row[x]];
          ++partial[1][row[x + 1]];
          ++partial[2][row[x + 2]];
          ++partial[3][row[x + 3]];
        }
        for (; x < tile_.width; ++x) ++histogram[row[x]];
      }
      for (int i = 0; i < kGreyLevels; ++i)
        histogram[i] += partial[0][i] + partial[1][i] + partial[2][i] + partial[3][i];
      // Clip and hand the excess out evenly, the remainder from the darkest level up with
      // cv::CLAHE's stride.
      if (clip > 0) {
        int clipped = 0;
        for (int& count : histogram) {
          if (count > clip) {
            clipped += count - clip;
            count = clip;
          }
        }
        const int each = clipped / kGreyLevels;
        int residual = clipped - each * kGreyLevels;
        for (int& count : histogram) count += each;
        if (residual != 0) {
          const int stride = std::max(kGreyLevels / residual, 1);
          for (int i = 0; i < kGreyLevels && residual > 0; i += stride, --residual) ++histogram[i];
        }
      }
      std::uint8_t* lut = &tile_luts_[(ty * tiles_ + tx) * kGreyLevels];
      int sum = 0;
      for (int i = 0; i < kGreyLevels; ++i) {
        sum += histogram[i];
        lut[i] = cv::saturate_cast<std::uint8_t>(sum * scale);
      }
    }
    for (int pair = 0; pair <= tiles_; ++pair) {
      const std::uint8_t* left = &tile_luts_[(ty * tiles_ + std::max(pair - 1, 0)) * kGreyLevels];
      const std::uint8_t* right =
          &tile_luts_[(ty * tiles_ + std::min(pair, tiles_ - 1)) * kGreyLevels];
      std::uint16_t* both = &pair_luts_[(ty * (tiles_ + 1) + pair) * kGreyLevels];
      for (int i = 0; i < kGreyLevels; ++i)
        both[i] = static_cast<std::uint16_t>(left[i] | (right[i] << 8));
    }
  }
}

void Clahe::blend(const cv::Mat& gray, cv::Mat& out) const {
  const float inverse_tile_height = 1.0f / tile_.height;
  const int pair_stride = (tiles_ + 1) * kGreyLevels;
  for (int y = 0; y < size_.height; ++y) {
    const std::uint8_t* in = gray.ptr<std::uint8_t>(y);
    std::uint8_t* target = out.ptr<std::uint8_t>(y);
    const float tile_y = y * inverse_tile_height - 0.5f;
    const int upper = static_cast<int>(std::floor(tile_y));
    const float weight_lower = tile_y - upper, weight_upper = 1.0f - weight_lower;
    const std::uint16_t* upper_luts = &pair_luts_[std::max(upper, 0) * pair_stride];
    const std::uint16_t* lower_luts = &pair_luts_[std::min(upper + 1, tiles_ - 1) * pair_stride];
    int x = 0;
#if defined(__SSE2__)
    const __m128 w_upper = _mm_set1_ps(weight_upper), w_lower = _mm_set1_ps(weight_lower);
    const __m128i low_byte = _mm_set1_epi32(0xff);
    for (; x + 8 <= size_.width; x += 8) {
      alignas(16) std::int32_t uppers[8], lowers[8];
      for (int k = 0; k < 8; ++k) {
        const int index = column_pair_[x + k] * kGreyLevels + in[x + k];
        uppers[k] = upper_luts[index];
        lowers[k] = lower_luts[index];
      }
      __m128i rounded[2];
      for (int h = 0; h < 2; ++h) {
        const __m128i up = _mm_load_si128(reinterpret_cast<const __m128i*>(uppers + 4 * h));
        const __m128i low = _mm_load_si128(reinterpret_cast<const __m128i*>(lowers + 4 * h));
        const __m128 wl = _mm_loadu_ps(&weight_left_[x + 4 * h]);
        const __m128 wr = _mm_loadu_ps(&weight_right_[x + 4 * h]);
        // (a wl + b wr) wu + (c wl + d wr) wd, as cv::CLAHE computes it.
        const auto row = [&](__m128i both) {
          const __m128 left = _mm_cvtepi32_ps(_mm_and_si128(both, low_byte));
          const __m128 right = _mm_cvtepi32_ps(_mm_srli_epi32(both, 8));
          return _mm_add_ps(_mm_mul_ps(left, wl), _mm_mul_ps(right, wr));
        };
        const __m128 value =
            _mm_add_ps(_mm_mul_ps(row(up), w_upper), _mm_mul_ps(row(low), w_lower));
        rounded[h] = _mm_cvtps_epi32(value);  // to nearest, ties to even, as cvRound
      }
      const __m128i words = _mm_packs_epi32(rounded[0], rounded[1]);
      _mm_storel_epi64(reinterpret_cast<__m128i*>(target + x), _mm_packus_epi16(words, words));
    }
#endif
    for (; x < size_.width; ++x) {
      const int index = column_pair_[x] * kGreyLevels + in[x];
      const int up = upper_luts[index], low = lower_luts[index];
      const float value =
          ((up & 0xff) * weight_left_[x] + (up >> 8) * weight_right_[x]) * weight_upper +
          ((low & 0xff) * weight_left_[x] + (low >> 8) * weight_right_[x]) * weight_lower;
      target[x] = cv::saturate_cast<std::uint8_t>(value);
    }
  }
}

}  // namespace alvio
