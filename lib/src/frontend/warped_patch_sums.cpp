#include "alvio/frontend/warped_patch_sums.h"

#include <algorithm>

#if ALVIO_AVX2_CODE
#include <immintrin.h>
#endif

namespace alvio {
namespace {

struct Warp {
  float a00, a01, a10, a11;
};

Warp floatWarp(const Eigen::Matrix2d& A) {
  return {static_cast<float>(A(0, 0)), static_cast<float>(A(0, 1)), static_cast<float>(A(1, 0)),
          static_cast<float>(A(1, 1))};
}

// The bilinear sample at (u, v), as both paths compute it.
inline float sampleAt(const uchar* data, std::size_t step, float u, float v) {
  const int iu = static_cast<int>(u), iv = static_cast<int>(v);
  const float fx = u - iu, fy = v - iv;
  const uchar* row0 = data + iv * step + iu;
  const uchar* row1 = row0 + step;
  const float top = row0[0] + fx * (row0[1] - row0[0]);
  const float bottom = row1[0] + fx * (row1[1] - row1[0]);
  return top + fy * (bottom - top);
}

void warpedSumsBaseline(const cv::Mat& image, const Warp& a, double qx, double qy, int n,
                        const float* packed, float* s2, float* sums) {
  const int h = n / 2;
  const uchar* data = image.data;
  const std::size_t step = image.step[0];
  float acc[8] = {};
  float sum2 = 0;
  const float* block = packed;
  for (int r = 0; r < n; ++r) {
    const float y = static_cast<float>(r - h);
    // Along a row the sample moves by A's first column per pixel.
    float u = static_cast<float>(qx) - a.a00 * h + a.a01 * y;
    float v = static_cast<float>(qy) - a.a10 * h + a.a11 * y;
    for (int c = 0; c < n; ++c, u += a.a00, v += a.a10, block += 8) {
      const float val = sampleAt(data, step, u, v);
      sum2 += val * val;
      for (int i = 0; i < 8; ++i) acc[i] += val * block[i];
    }
  }
  *s2 = sum2;
  for (int i = 0; i < 8; ++i) sums[i] = acc[i];
}

#if ALVIO_AVX2_CODE
constexpr int kMaxWideSide = 64;

// Eight samples at a time: positions from the same running sums as the baseline's, each
// sample's two pixel pairs gathered as 32-bit words, the arithmetic in the same float
// operations; then each sample's products added in order, the eight sums in one register.
ALVIO_AVX2 void warpedSumsWide(const cv::Mat& image, const Warp& a, double qx, double qy, int n,
                               const float* packed, float* s2, float* sums) {
  const int h = n / 2;
  const uchar* data = image.data;
  const std::size_t step = image.step[0];
  const int* words = reinterpret_cast<const int*>(data);
  const __m256i step8 = _mm256_set1_epi32(static_cast<int>(step));
  const __m256i low_byte = _mm256_set1_epi32(0xff);
  __m256 acc = _mm256_setzero_ps();
  float sum2 = 0;
  const float* block = packed;
  alignas(32) float us[kMaxWideSide], vs[kMaxWideSide], values[kMaxWideSide];
  for (int r = 0; r < n; ++r) {
    const float y = static_cast<float>(r - h);
    float u = static_cast<float>(qx) - a.a00 * h + a.a01 * y;
    float v = static_cast<float>(qy) - a.a10 * h + a.a11 * y;
    for (int c = 0; c < n; ++c, u += a.a00, v += a.a10) {
      us[c] = u;
      vs[c] = v;
    }
    int c = 0;
    for (; c + 8 <= n; c += 8) {
      const __m256 u8 = _mm256_load_ps(us + c), v8 = _mm256_load_ps(vs + c);
      const __m256i iu = _mm256_cvttps_epi32(u8), iv = _mm256_cvttps_epi32(v8);
      const __m256 fx = _mm256_sub_ps(u8, _mm256_cvtepi32_ps(iu));
      const __m256 fy = _mm256_sub_ps(v8, _mm256_cvtepi32_ps(iv));
      const __m256i offset = _mm256_add_epi32(_mm256_mullo_epi32(iv, step8), iu);
      const __m256i pair0 = _mm256_i32gather_epi32(words, offset, 1);
      const __m256i pair1 = _mm256_i32gather_epi32(words, _mm256_add_epi32(offset, step8), 1);
      const __m256i l0 = _mm256_and_si256(pair0, low_byte);
      const __m256i r0 = _mm256_and_si256(_mm256_srli_epi32(pair0, 8), low_byte);
      const __m256i l1 = _mm256_and_si256(pair1, low_byte);
      const __m256i r1 = _mm256_and_si256(_mm256_srli_epi32(pair1, 8), low_byte);
      const __m256 top = _mm256_add_ps(
          _mm256_cvtepi32_ps(l0), _mm256_mul_ps(fx, _mm256_cvtepi32_ps(_mm256_sub_epi32(r0, l0))));
      const __m256 bottom = _mm256_add_ps(
          _mm256_cvtepi32_ps(l1), _mm256_mul_ps(fx, _mm256_cvtepi32_ps(_mm256_sub_epi32(r1, l1))));
      _mm256_store_ps(values + c,
                      _mm256_add_ps(top, _mm256_mul_ps(fy, _mm256_sub_ps(bottom, top))));
    }
    for (; c < n; ++c) values[c] = sampleAt(data, step, us[c], vs[c]);
    for (c = 0; c < n; ++c, block += 8) {
      const float val = values[c];
      sum2 += val * val;
      acc = _mm256_add_ps(acc, _mm256_mul_ps(_mm256_set1_ps(val), _mm256_loadu_ps(block)));
    }
  }
  *s2 = sum2;
  _mm256_storeu_ps(sums, acc);
}

// The gathers read 4 bytes from each sample's top-left pixel, 2 more than the baseline: past
// the buffer's end only if a sample's lower pixel lies in the image's last row, which the
// caller allows. The warped window's corners bound its rows.
bool gathersStayInside(const cv::Mat& image, const Warp& a, double qx, double qy, int n) {
  const int h = n / 2;
  float lowest = 0;
  for (int cy : {-h, h})
    for (int cx : {-h, h})
      lowest = std::max(lowest, static_cast<float>(qy) + a.a10 * cx + a.a11 * cy);
  return lowest + 1.0f < static_cast<float>(image.rows - 2);
}
#endif

}  // namespace

void warpedPatchSums(const cv::Mat& image, const Eigen::Matrix2d& A, double qx, double qy, int n,
                     const float* packed, float* s2, float* sums, Vectors vectors) {
  const Warp a = floatWarp(A);
#if ALVIO_AVX2_CODE
  if (vectors == Vectors::kWidest && n <= kMaxWideSide && cpuHasAvx2() &&
      gathersStayInside(image, a, qx, qy, n))
    return warpedSumsWide(image, a, qx, qy, n, packed, s2, sums);
#else
  (void)vectors;
#endif
  warpedSumsBaseline(image, a, qx, qy, n, packed, s2, sums);
}

}  // namespace alvio
