#include "alvio/lines/image_undistorter.h"

#include <cstring>
#include <opencv2/imgproc.hpp>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "alvio/camera/camera_model.h"

namespace alvio {
namespace {
// cv::remap's fixed-point bilinear interpolation: sub-pixel positions in 1/32 px, so each
// weight is a product of two of 0..32 and the four sum to 1024.
constexpr int kFractionBits = 5;
constexpr int kFractions = 1 << kFractionBits;
constexpr int kWeightBits = 2 * kFractionBits;

inline std::uint8_t blend(int top_left, int top_right, int bottom_left, int bottom_right, int fx,
                          int fy) {
  // Exactly sum(w_i * p_i) with w = (32 - fx)(32 - fy), fx (32 - fy), (32 - fx) fy, fx fy,
  // rounded as cv::remap rounds (its weights are these times 32, its shift 15).
  const int top = top_left * kFractions + (top_right - top_left) * fx;
  const int bottom = bottom_left * kFractions + (bottom_right - bottom_left) * fx;
  return static_cast<std::uint8_t>(
      (top * kFractions + (bottom - top) * fy + (1 << (kWeightBits - 1))) >> kWeightBits);
}
}  // namespace

ImageUndistorter::ImageUndistorter(const CameraOptions& camera)
    : size_(camera.width, camera.height),
      fx_(camera.intrinsics[0]),
      fy_(camera.intrinsics[1]),
      cx_(camera.intrinsics[2]),
      cy_(camera.intrinsics[3]) {
  has_distortion_ = false;
  for (double c : camera.distortion_coefficients) has_distortion_ |= c != 0.0;
  valid_mask_ = cv::Mat(size_, CV_8UC1, cv::Scalar(255));
  if (!has_distortion_) return;

  // For every pinhole pixel: its normalised ray, distorted into the raw image.
  const auto model = CameraModel::create(camera);
  cv::Mat map_x(size_, CV_32FC1), map_y(size_, CV_32FC1);
  for (int v = 0; v < size_.height; ++v) {
    for (int u = 0; u < size_.width; ++u) {
      const Eigen::Vector2d raw = model->distort(pixelToNormalised(Eigen::Vector2d(u, v)));
      map_x.at<float>(v, u) = static_cast<float>(raw.x());
      map_y.at<float>(v, u) = static_cast<float>(raw.y());
    }
  }
  // Fixed-point tables make cv::remap several times faster than float ones.
  cv::convertMaps(map_x, map_y, map_xy_, map_frac_, CV_16SC2);
  const int width = size_.width, height = size_.height;
  source_offset_.assign(static_cast<std::size_t>(width) * height, 0);
  source_fraction_.resize(source_offset_.size());
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const cv::Vec2s source = map_xy_.at<cv::Vec2s>(v, u);
      const int index = v * width + u;
      const int fraction = map_frac_.at<std::uint16_t>(v, u) & (kFractions * kFractions - 1);
      source_fraction_[index] = static_cast<std::uint16_t>(fraction);
      // cv::remap's own test for a neighbourhood inside the image.
      if (static_cast<unsigned>(source[0]) < static_cast<unsigned>(width - 1) &&
          static_cast<unsigned>(source[1]) < static_cast<unsigned>(height - 1))
        source_offset_[index] = source[1] * width + source[0];
      else
        border_pixels_.push_back({index, source[0], source[1], fraction});
    }
  }
  const cv::Mat ones(size_, CV_8UC1, cv::Scalar(255));
  cv::remap(ones, valid_mask_, map_xy_, map_frac_, cv::INTER_NEAREST, cv::BORDER_CONSTANT,
            cv::Scalar(0));
}

cv::Mat ImageUndistorter::undistort(const cv::Mat& raw) const {
  if (!has_distortion_) return raw;
  if (raw.type() == CV_8UC1 && raw.size() == size_ && raw.isContinuous()) return remapBilinear(raw);
  cv::Mat out;
  cv::remap(raw, out, map_xy_, map_frac_, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  return out;
}

// cv::remap's result from tables made once (cv::remap converts its tables block by block on
// every call): 0.34x its time on a 752x480 image with SSE2, 0.7x without.
cv::Mat ImageUndistorter::remapBilinear(const cv::Mat& raw) const {
  cv::Mat out(size_, CV_8UC1);
  const std::uint8_t* source = raw.ptr<std::uint8_t>();
  std::uint8_t* target = out.ptr<std::uint8_t>();
  const int width = size_.width, height = size_.height;
  const std::size_t count = source_offset_.size();
  std::size_t i = 0;
#if defined(__SSE2__)
  // Eight pixels at a time: their four sources fetched one by one, the arithmetic in SSE2 in
  // the same integers as blend() (both rows' blends fit in 16 bits, the last sum in 32).
  const __m128i low_byte = _mm_set1_epi16(0xff), fraction_mask = _mm_set1_epi16(kFractions - 1);
  const __m128i full = _mm_set1_epi16(kFractions), half = _mm_set1_epi32(1 << (kWeightBits - 1));
  for (; i + 8 <= count; i += 8) {
    alignas(16) std::uint16_t tops[8], bottoms[8];
    for (int k = 0; k < 8; ++k) {
      const std::uint8_t* p = source + source_offset_[i + k];
      std::memcpy(&tops[k], p, 2);
      std::memcpy(&bottoms[k], p + width, 2);
    }
    const __m128i top_pair = _mm_load_si128(reinterpret_cast<const __m128i*>(tops));
    const __m128i bottom_pair = _mm_load_si128(reinterpret_cast<const __m128i*>(bottoms));
    const __m128i fraction =
        _mm_loadu_si128(reinterpret_cast<const __m128i*>(source_fraction_.data() + i));
    const __m128i fx = _mm_and_si128(fraction, fraction_mask);
    const __m128i fy = _mm_srli_epi16(fraction, kFractionBits);
    const auto row = [&](__m128i pair) {  // left * 32 + (right - left) * fx, little-endian
      const __m128i left = _mm_and_si128(pair, low_byte), right = _mm_srli_epi16(pair, 8);
      return _mm_add_epi16(_mm_slli_epi16(left, kFractionBits),
                           _mm_mullo_epi16(_mm_sub_epi16(right, left), fx));
    };
    const __m128i top = row(top_pair), bottom = row(bottom_pair);
    const __m128i wy = _mm_sub_epi16(full, fy);
    __m128i lo = _mm_madd_epi16(_mm_unpacklo_epi16(top, bottom), _mm_unpacklo_epi16(wy, fy));
    __m128i hi = _mm_madd_epi16(_mm_unpackhi_epi16(top, bottom), _mm_unpackhi_epi16(wy, fy));
    lo = _mm_srai_epi32(_mm_add_epi32(lo, half), kWeightBits);
    hi = _mm_srai_epi32(_mm_add_epi32(hi, half), kWeightBits);
    const __m128i words = _mm_packs_epi32(lo, hi);
    _mm_storel_epi64(reinterpret_cast<__m128i*>(target + i), _mm_packus_epi16(words, words));
  }
#endif
  for (; i < count; ++i) {
    const std::uint8_t* p = source + source_offset_[i];
    const int fraction = source_fraction_[i];
    target[i] = blend(p[0], p[1], p[width], p[width + 1], fraction & (kFractions - 1),
                      fraction >> kFractionBits);
  }
  // Source pixels outside the raw image are black, as with cv::BORDER_CONSTANT.
  const auto at = [&](int x, int y) -> int {
    return x >= 0 && y >= 0 && x < width && y < height ? source[y * width + x] : 0;
  };
  for (const BorderPixel& b : border_pixels_) {
    const int x = b.source_x, y = b.source_y;
    if (x >= width || x + 1 < 0 || y >= height || y + 1 < 0) {
      target[b.index] = 0;
      continue;
    }
    target[b.index] = blend(at(x, y), at(x + 1, y), at(x, y + 1), at(x + 1, y + 1),
                            b.fraction & (kFractions - 1), b.fraction >> kFractionBits);
  }
  return out;
}

}  // namespace alvio
