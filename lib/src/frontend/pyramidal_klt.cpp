#include "alvio/frontend/pyramidal_klt.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <opencv2/video/tracking.hpp>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace alvio {
namespace {

void openCvKlt(const std::vector<cv::Mat>& from_pyramid, const std::vector<cv::Mat>& to_pyramid,
               const std::vector<cv::Point2f>& from, std::vector<cv::Point2f>* to,
               std::vector<uchar>* status, cv::Size window, int max_level,
               const cv::TermCriteria& stop, bool use_initial_flow) {
  cv::calcOpticalFlowPyrLK(from_pyramid, to_pyramid, from, *to, *status, cv::noArray(), window,
                           max_level, stop, use_initial_flow ? cv::OPTFLOW_USE_INITIAL_FLOW : 0);
}

#if defined(__SSE2__)

// OpenCV's fixed point: bilinear weights in 14 bits; image values keep 5 more bits.
constexpr int kWeightBits = 14;
constexpr float kSumScale = 1.f / (1 << 20);
constexpr float kMinEigenThreshold = 1e-4f;

// A pyramid's levels and the step between its images (2 when each has its gradients after it).
struct PyramidLayout {
  int levels = -1;
  int step = 1;
};

PyramidLayout layoutOf(const std::vector<cv::Mat>& pyramid) {
  PyramidLayout layout;
  layout.levels = static_cast<int>(pyramid.size()) - 1;
  if (layout.levels % 2 == 1 && pyramid[0].channels() * 2 == pyramid[1].channels() &&
      pyramid[1].depth() == CV_16S) {
    layout.step = 2;
    layout.levels /= 2;
  }
  return layout;
}

// The border every level above the first needs around it (the window), as OpenCV checks.
bool padded(const std::vector<cv::Mat>& pyramid, const PyramidLayout& layout, cv::Size window) {
  if (layout.levels <= 0) return true;
  cv::Size full;
  cv::Point offset;
  const cv::Mat& level1 = pyramid[layout.step];
  level1.locateROI(full, offset);
  return offset.x >= window.width && offset.y >= window.height &&
         offset.x + level1.cols + window.width <= full.width &&
         offset.y + level1.rows + window.height <= full.height;
}

// OpenCV's weights (w00, w01) and (w10, w11) as 16-bit pairs, for _mm_madd_epi16.
struct Bilinear {
  __m128i top, bottom;
};

inline int pairOf(int left, int right) {
  return static_cast<int>(static_cast<uint32_t>(static_cast<uint16_t>(left)) |
                          (static_cast<uint32_t>(static_cast<uint16_t>(right)) << 16));
}

inline Bilinear bilinear(float a, float b) {
  const int w00 = cvRound((1.f - a) * (1.f - b) * (1 << kWeightBits));
  const int w01 = cvRound(a * (1.f - b) * (1 << kWeightBits));
  const int w10 = cvRound((1.f - a) * b * (1 << kWeightBits));
  const int w11 = (1 << kWeightBits) - w00 - w01 - w10;
  return {_mm_set1_epi32(pairOf(w00, w01)), _mm_set1_epi32(pairOf(w10, w11))};
}

// Bilinear interpolation of eight 16-bit values: v00 a row, v01 its right neighbours, v10 and
// v11 the same one row below; rounded and shifted right by kShift bits (OpenCV's CV_DESCALE).
template <int kShift>
inline __m128i interpolate(__m128i v00, __m128i v01, __m128i v10, __m128i v11, const Bilinear& w) {
  const __m128i round = _mm_set1_epi32(1 << (kShift - 1));
  const __m128i lo =
      _mm_add_epi32(_mm_add_epi32(_mm_madd_epi16(_mm_unpacklo_epi16(v00, v01), w.top), round),
                    _mm_madd_epi16(_mm_unpacklo_epi16(v10, v11), w.bottom));
  const __m128i hi =
      _mm_add_epi32(_mm_add_epi32(_mm_madd_epi16(_mm_unpackhi_epi16(v00, v01), w.top), round),
                    _mm_madd_epi16(_mm_unpackhi_epi16(v10, v11), w.bottom));
  return _mm_packs_epi32(_mm_srai_epi32(lo, kShift), _mm_srai_epi32(hi, kShift));
}

// Pixels p[0..7] of an 8-bit image, interpolated between p[x], p[x + 1] and the row below;
// in 1/32 grey levels, as int16.
inline __m128i interpolate8(const uchar* p, std::ptrdiff_t step, const Bilinear& w) {
  const auto load = [](const uchar* q) {
    return _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(q)),
                             _mm_setzero_si128());
  };
  return interpolate<kWeightBits - 5>(load(p), load(p + 1), load(p + step), load(p + step + 1), w);
}

// Four pixels' gradients (x, y interleaved int16 at d[0..7]), interpolated like interpolate8:
// Ix0 Iy0 Ix1 Iy1 Ix2 Iy2 Ix3 Iy3.
inline __m128i interpolateGradients4(const short* d, std::ptrdiff_t step, const Bilinear& w) {
  const auto load = [](const short* q) {
    return _mm_loadu_si128(reinterpret_cast<const __m128i*>(q));
  };
  return interpolate<kWeightBits>(load(d), load(d + 2), load(d + step), load(d + step + 2), w);
}

// The x and y gradients of four interpolated pixels (Ix0 Iy0 Ix1 Iy1 ...) as floats.
inline __m128 gradientX(__m128i g) {
  return _mm_cvtepi32_ps(_mm_srai_epi32(_mm_slli_epi32(g, 16), 16));
}
inline __m128 gradientY(__m128i g) {
  return _mm_cvtepi32_ps(_mm_srai_epi32(g, 16));
}

// OpenCV's v_reduce_sum: (l0 + l2) + (l1 + l3).
inline float reduceSum(__m128 v) {
  v = _mm_add_ps(v, _mm_castsi128_ps(_mm_srli_si128(_mm_castps_si128(v), 8)));
  v = _mm_add_ps(v, _mm_castsi128_ps(_mm_srli_si128(_mm_castps_si128(v), 4)));
  return _mm_cvtss_f32(v);
}

#if ALVIO_AVX2_CODE

// Sixteen pixels at a time: two of OpenCV's 8-pixel blocks side by side, one in each 128-bit
// half. Every integer step is the same as in the 8-pixel code, only twice as wide; the float
// sums still add one block after the other, in OpenCV's order.
struct Bilinear2 {
  __m256i top, bottom;
};

ALVIO_AVX2 inline Bilinear2 widen(const Bilinear& w) {
  return {_mm256_broadcastsi128_si256(w.top), _mm256_broadcastsi128_si256(w.bottom)};
}

template <int kShift>
ALVIO_AVX2 inline __m256i interpolate2(__m256i v00, __m256i v01, __m256i v10, __m256i v11,
                                       const Bilinear2& w) {
  const __m256i round = _mm256_set1_epi32(1 << (kShift - 1));
  const __m256i lo = _mm256_add_epi32(
      _mm256_add_epi32(_mm256_madd_epi16(_mm256_unpacklo_epi16(v00, v01), w.top), round),
      _mm256_madd_epi16(_mm256_unpacklo_epi16(v10, v11), w.bottom));
  const __m256i hi = _mm256_add_epi32(
      _mm256_add_epi32(_mm256_madd_epi16(_mm256_unpackhi_epi16(v00, v01), w.top), round),
      _mm256_madd_epi16(_mm256_unpackhi_epi16(v10, v11), w.bottom));
  return _mm256_packs_epi32(_mm256_srai_epi32(lo, kShift), _mm256_srai_epi32(hi, kShift));
}

ALVIO_AVX2 inline __m256i loadWidened(const uchar* q) {
  return _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(q)));
}

// interpolate8 for p[0..15]: pixels 0-7 in the low half, 8-15 in the high half.
ALVIO_AVX2 inline __m256i interpolate16(const uchar* p, std::ptrdiff_t step, const Bilinear2& w) {
  return interpolate2<kWeightBits - 5>(loadWidened(p), loadWidened(p + 1), loadWidened(p + step),
                                       loadWidened(p + step + 1), w);
}

ALVIO_AVX2 inline __m256i loadShorts(const short* q) {
  return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(q));
}

// interpolateGradients4 for eight pixels: pixels 0-3 in the low half, 4-7 in the high half.
ALVIO_AVX2 inline __m256i interpolateGradients8(const short* d, std::ptrdiff_t step,
                                                const Bilinear2& w) {
  return interpolate2<kWeightBits>(loadShorts(d), loadShorts(d + 2), loadShorts(d + step),
                                   loadShorts(d + step + 2), w);
}
#endif

// One pyramid level for a range of points: OpenCV's LKTrackerInvoker, same arithmetic.
class LevelTracker {
 public:
  LevelTracker(const cv::Mat& I, const cv::Mat& dI, const cv::Mat& J, cv::Size window, int level,
               int max_level, int max_iterations, double epsilon_squared, bool use_initial_flow,
               bool wide, const cv::Point2f* from, cv::Point2f* to, uchar* status)
      : I_(I),
        dI_(dI),
        J_(J),
        width_(window.width),
        height_(window.height),
        simd_(8 * (window.width / 8)),
        tail_(window.width % 8),
        level_(level),
        max_level_(max_level),
        max_iterations_(max_iterations),
        epsilon_squared_(epsilon_squared),
        use_initial_flow_(use_initial_flow),
        wide_(wide),
        from_(from),
        to_(to),
        status_(status) {}

  void operator()(const cv::Range& range) const {
    Buffers buffers(width_, height_, simd_);
    for (int i = range.start; i < range.end; ++i) trackPoint(i, &buffers);
  }

 private:
  // The first image's window: values, gradients in OpenCV's pairing for its 8-pixel blocks
  // (two blocks' pairings interleaved by halves when wide_), and the gradients of each row's
  // remaining pixels as floats.
  struct Buffers {
    Buffers(int width, int height, int simd)
        : values(static_cast<std::size_t>(width) * height),
          paired(static_cast<std::size_t>(height) * 2 * simd),
          tail_x(static_cast<std::size_t>(height) * 8),
          tail_y(static_cast<std::size_t>(height) * 8) {}
    std::vector<short> values;
    std::vector<short> paired;
    // Per row, the last 8 pixels' gradients as floats (the tail is their last tail_ lanes).
    std::vector<float> tail_x, tail_y;
  };

  void trackPoint(int i, Buffers* buf) const {
    const cv::Point2f half((width_ - 1) * 0.5f, (height_ - 1) * 0.5f);
    cv::Point2f prev = from_[i] * static_cast<float>(1. / (1 << level_));
    cv::Point2f next;
    if (level_ == max_level_)
      next = use_initial_flow_ ? to_[i] * static_cast<float>(1. / (1 << level_)) : prev;
    else
      next = to_[i] * 2.f;
    to_[i] = next;

    prev -= half;
    const cv::Point iprev(cvFloor(prev.x), cvFloor(prev.y));
    if (iprev.x < -width_ || iprev.x >= dI_.cols || iprev.y < -height_ || iprev.y >= dI_.rows) {
      if (level_ == 0) status_[i] = false;
      return;
    }
    float A11, A12, A22;
    takeTemplate(iprev, bilinear(prev.x - iprev.x, prev.y - iprev.y), buf, &A11, &A12, &A22);

    float D = A11 * A22 - A12 * A12;
    const float min_eigen = (A22 + A11 - std::sqrt((A11 - A22) * (A11 - A22) + 4.f * A12 * A12)) /
                            (2 * width_ * height_);
    if (min_eigen < kMinEigenThreshold || D < FLT_EPSILON) {
      if (level_ == 0) status_[i] = false;
      return;
    }
    D = 1.f / D;

    next -= half;
    cv::Point2f prev_delta;
    for (int j = 0; j < max_iterations_; ++j) {
      const cv::Point inext(cvFloor(next.x), cvFloor(next.y));
      if (inext.x < -width_ || inext.x >= J_.cols || inext.y < -height_ || inext.y >= J_.rows) {
        if (level_ == 0) status_[i] = false;
        break;
      }
      float b1, b2;
      mismatch(inext, bilinear(next.x - inext.x, next.y - inext.y), *buf, &b1, &b2);
      const cv::Point2f delta(static_cast<float>((A12 * b2 - A22 * b1) * D),
                              static_cast<float>((A12 * b1 - A11 * b2) * D));
      next += delta;
      to_[i] = next + half;
      if (delta.ddot(delta) <= epsilon_squared_) break;
      if (j > 0 && std::abs(delta.x + prev_delta.x) < 0.01 &&
          std::abs(delta.y + prev_delta.y) < 0.01) {
        to_[i] -= delta * 0.5f;
        break;
      }
      prev_delta = delta;
    }
  }

  // The window around `at` in the first image, and its gradients' products summed as OpenCV
  // sums them: pixels 0..simd_-1 of each row in four float lanes, the rest one by one.
  void takeTemplate(cv::Point at, const Bilinear& w, Buffers* buf, float* A11, float* A12,
                    float* A22) const {
    const std::ptrdiff_t step_i = stepOf(I_), step_d = stepOf(dI_);
    const Window window{I_.ptr() + at.y * step_i + at.x,
                        dI_.ptr<short>() + at.y * step_d + at.x * 2, step_i, step_d};
    ProductSums q{_mm_setzero_ps(), _mm_setzero_ps(), _mm_setzero_ps()};
    TailSums tails;
#if ALVIO_AVX2_CODE
    if (wide_)
      templateRowsWide(window, w, buf, &q, &tails);
    else
#endif
      templateRows(window, w, buf, &q, &tails);
    *A11 = (tails.a11 + reduceSum(q.a11)) * kSumScale;
    *A12 = (tails.a12 + reduceSum(q.a12)) * kSumScale;
    *A22 = (tails.a22 + reduceSum(q.a22)) * kSumScale;
  }

  // The window around `at` in the second image against the template: the sums of the
  // differences times the gradients, in OpenCV's order.
  void mismatch(cv::Point at, const Bilinear& w, const Buffers& buf, float* b1, float* b2) const {
    const std::ptrdiff_t step_j = stepOf(J_);
    const uchar* image = J_.ptr() + at.y * step_j + at.x;
    __m128 qb0 = _mm_setzero_ps(), qb1 = _mm_setzero_ps();
    float ib1 = 0, ib2 = 0;
#if ALVIO_AVX2_CODE
    if (wide_)
      mismatchRowsWide(image, step_j, w, buf, &qb0, &qb1, &ib1, &ib2);
    else
#endif
      mismatchRows(image, step_j, w, buf, &qb0, &qb1, &ib1, &ib2);
    // OpenCV's lane order: (qb0 + qb1) interleaved by pairs, then each half reduced.
    const __m128i qb =
        _mm_shuffle_epi32(_mm_castps_si128(_mm_add_ps(qb0, qb1)), _MM_SHUFFLE(3, 1, 2, 0));
    ib1 += reduceSum(_mm_castsi128_ps(_mm_unpacklo_epi64(qb, _mm_setzero_si128())));
    ib2 += reduceSum(_mm_castsi128_ps(_mm_unpackhi_epi64(qb, _mm_setzero_si128())));
    *b1 = ib1 * kSumScale;
    *b2 = ib2 * kSumScale;
  }

  // The template's window: its first pixel and gradient, and the rows' steps (in elements).
  struct Window {
    const uchar* image;
    const short* gradients;
    std::ptrdiff_t image_step, gradient_step;
  };
  // The four float lanes of the gradients' products, and the rows' remainders added one by one.
  struct ProductSums {
    __m128 a11, a12, a22;
  };
  struct TailSums {
    float a11 = 0, a12 = 0, a22 = 0;
  };

  static std::ptrdiff_t stepOf(const cv::Mat& m) {
    return static_cast<std::ptrdiff_t>(m.step / m.elemSize1());
  }

  // The products of four interpolated pixels' gradients (Ix0 Iy0 Ix1 Iy1 ...) added to q.
  static void accumulate(__m128i g, ProductSums* q) {
    const __m128 fx = gradientX(g), fy = gradientY(g);
    q->a22 = _mm_add_ps(_mm_mul_ps(fy, fy), q->a22);
    q->a12 = _mm_add_ps(_mm_mul_ps(fx, fy), q->a12);
    q->a11 = _mm_add_ps(_mm_mul_ps(fx, fx), q->a11);
  }

  // One of OpenCV's 8-pixel blocks of the template, at x of a row.
  static void templateBlock(const uchar* src, const short* dsrc, int x, const Window& window,
                            const Bilinear& w, short* values, short* paired, ProductSums* q) {
    _mm_storeu_si128(reinterpret_cast<__m128i*>(values + x),
                     interpolate8(src + x, window.image_step, w));
    const __m128i g0 = interpolateGradients4(dsrc + 2 * x, window.gradient_step, w);
    const __m128i g1 = interpolateGradients4(dsrc + 2 * x + 8, window.gradient_step, w);
    accumulate(g0, q);
    accumulate(g1, q);
    // Ix0 Ix4 Iy0 Iy4 Ix1 Ix5 Iy1 Iy5 | Ix2 Ix6 Iy2 Iy6 Ix3 Ix7 Iy3 Iy7, as OpenCV pairs
    // them with the differences.
    _mm_storeu_si128(reinterpret_cast<__m128i*>(paired + 2 * x), _mm_unpacklo_epi16(g0, g1));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(paired + 2 * x + 8), _mm_unpackhi_epi16(g0, g1));
  }

  void templateRows(const Window& window, const Bilinear& w, Buffers* buf, ProductSums* q,
                    TailSums* tails) const {
    for (int y = 0; y < height_; ++y) {
      const uchar* src = window.image + y * window.image_step;
      const short* dsrc = window.gradients + y * window.gradient_step;
      short* values = buf->values.data() + static_cast<std::ptrdiff_t>(y) * width_;
      short* paired = buf->paired.data() + static_cast<std::ptrdiff_t>(y) * 2 * simd_;
      for (int x = 0; x < simd_; x += 8) templateBlock(src, dsrc, x, window, w, values, paired, q);
      if (tail_ > 0) templateTail(y, src, dsrc, window, w, buf, tails);
    }
  }

  // A row's last tail_ pixels: OpenCV adds their products one by one. Added as each row ends,
  // the chains overlap the next rows' work.
  void templateTail(int y, const uchar* src, const short* dsrc, const Window& window,
                    const Bilinear& w, Buffers* buf, TailSums* tails) const {
    const int first = 8 - tail_;  // the tail's first lane in each row's last 8 pixels
    const int x = width_ - 8;     // the last 8 pixels (overlapping the blocks)
    alignas(16) float p[24];
    short* values = buf->values.data() + static_cast<std::ptrdiff_t>(y) * width_;
    _mm_storeu_si128(reinterpret_cast<__m128i*>(values + x),
                     interpolate8(src + x, window.image_step, w));
    float* tx = buf->tail_x.data() + 8 * y;
    float* ty = buf->tail_y.data() + 8 * y;
    for (int half = 0; half < 2; ++half) {
      const __m128i g = interpolateGradients4(dsrc + 2 * x + 8 * half, window.gradient_step, w);
      const __m128 fx = gradientX(g), fy = gradientY(g);
      _mm_storeu_ps(tx + 4 * half, fx);
      _mm_storeu_ps(ty + 4 * half, fy);
      _mm_store_ps(p + 4 * half, _mm_mul_ps(fx, fx));
      _mm_store_ps(p + 8 + 4 * half, _mm_mul_ps(fx, fy));
      _mm_store_ps(p + 16 + 4 * half, _mm_mul_ps(fy, fy));
    }
    for (int k = first; k < 8; ++k) {
      tails->a11 += p[k];
      tails->a12 += p[8 + k];
      tails->a22 += p[16 + k];
    }
  }

  // One 8-pixel block of the second image against the template, at x of a row.
  static void mismatchBlock(const uchar* src, std::ptrdiff_t step_j, int x, const Bilinear& w,
                            const short* values, const short* paired, __m128* qb0, __m128* qb1) {
    const __m128i diff =
        _mm_sub_epi16(interpolate8(src + x, step_j, w),
                      _mm_loadu_si128(reinterpret_cast<const __m128i*>(values + x)));
    const __m128i d03 = _mm_unpacklo_epi16(diff, diff);  // d0 d0 d1 d1 d2 d2 d3 d3
    const __m128i d47 = _mm_unpackhi_epi16(diff, diff);
    const __m128i g0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(paired + 2 * x));
    const __m128i g1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(paired + 2 * x + 8));
    *qb0 = _mm_add_ps(*qb0, _mm_cvtepi32_ps(_mm_madd_epi16(_mm_unpacklo_epi16(d03, d47), g0)));
    *qb1 = _mm_add_ps(*qb1, _mm_cvtepi32_ps(_mm_madd_epi16(_mm_unpackhi_epi16(d03, d47), g1)));
  }

  void mismatchRows(const uchar* image, std::ptrdiff_t step_j, const Bilinear& w,
                    const Buffers& buf, __m128* qb0, __m128* qb1, float* ib1, float* ib2) const {
    for (int y = 0; y < height_; ++y) {
      const uchar* src = image + y * step_j;
      const short* values = buf.values.data() + static_cast<std::ptrdiff_t>(y) * width_;
      const short* paired = buf.paired.data() + static_cast<std::ptrdiff_t>(y) * 2 * simd_;
      for (int x = 0; x < simd_; x += 8) mismatchBlock(src, step_j, x, w, values, paired, qb0, qb1);
      if (tail_ > 0) mismatchTail(y, src, step_j, w, buf, ib1, ib2);
    }
  }

  // A row's last tail_ pixels, one by one as OpenCV adds them.
  void mismatchTail(int y, const uchar* src, std::ptrdiff_t step_j, const Bilinear& w,
                    const Buffers& buf, float* ib1, float* ib2) const {
    const int first = 8 - tail_;
    const int x = width_ - 8;
    alignas(16) float p[16];
    const short* values = buf.values.data() + static_cast<std::ptrdiff_t>(y) * width_;
    const __m128i diff =
        _mm_sub_epi16(interpolate8(src + x, step_j, w),
                      _mm_loadu_si128(reinterpret_cast<const __m128i*>(values + x)));
    const __m128 d03 = _mm_cvtepi32_ps(_mm_srai_epi32(_mm_unpacklo_epi16(diff, diff), 16));
    const __m128 d47 = _mm_cvtepi32_ps(_mm_srai_epi32(_mm_unpackhi_epi16(diff, diff), 16));
    const float* tx = buf.tail_x.data() + 8 * y;
    const float* ty = buf.tail_y.data() + 8 * y;
    _mm_store_ps(p, _mm_mul_ps(d03, _mm_loadu_ps(tx)));
    _mm_store_ps(p + 4, _mm_mul_ps(d47, _mm_loadu_ps(tx + 4)));
    _mm_store_ps(p + 8, _mm_mul_ps(d03, _mm_loadu_ps(ty)));
    _mm_store_ps(p + 12, _mm_mul_ps(d47, _mm_loadu_ps(ty + 4)));
    for (int k = first; k < 8; ++k) {
      *ib1 += p[k];
      *ib2 += p[8 + k];
    }
  }

#if ALVIO_AVX2_CODE
  // The products of eight pixels' gradients (pixels 0-3 in the low half, 4-7 in the high
  // half) added to q: the low half's, then the high half's, as two 4-pixel steps would.
  ALVIO_AVX2 static void accumulateWide(__m256i g, ProductSums* q) {
    const __m256 fx = _mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_slli_epi32(g, 16), 16));
    const __m256 fy = _mm256_cvtepi32_ps(_mm256_srai_epi32(g, 16));
    const __m256 yy = _mm256_mul_ps(fy, fy), xy = _mm256_mul_ps(fx, fy), xx = _mm256_mul_ps(fx, fx);
    q->a22 = _mm_add_ps(_mm256_castps256_ps128(yy), q->a22);
    q->a12 = _mm_add_ps(_mm256_castps256_ps128(xy), q->a12);
    q->a11 = _mm_add_ps(_mm256_castps256_ps128(xx), q->a11);
    q->a22 = _mm_add_ps(_mm256_extractf128_ps(yy, 1), q->a22);
    q->a12 = _mm_add_ps(_mm256_extractf128_ps(xy, 1), q->a12);
    q->a11 = _mm_add_ps(_mm256_extractf128_ps(xx, 1), q->a11);
  }

  // templateRows two blocks at a time. The paired gradients of a block pair are kept as
  // [lo(0) lo(1)] [hi(0) hi(1)], where lo and hi are templateBlock's two stores: each half then
  // meets its block's differences in mismatchRowsWide.
  ALVIO_AVX2 void templateRowsWide(const Window& window, const Bilinear& w1, Buffers* buf,
                                   ProductSums* q_out, TailSums* tails_out) const {
    // Not inlined into its caller (another target): sums kept in locals stay in registers.
    ProductSums sums = *q_out, *q = &sums;
    TailSums tail_sums = *tails_out, *tails = &tail_sums;
    const Bilinear2 w = widen(w1);
    for (int y = 0; y < height_; ++y) {
      const uchar* src = window.image + y * window.image_step;
      const short* dsrc = window.gradients + y * window.gradient_step;
      short* values = buf->values.data() + static_cast<std::ptrdiff_t>(y) * width_;
      short* paired = buf->paired.data() + static_cast<std::ptrdiff_t>(y) * 2 * simd_;
      int x = 0;
      for (; x + 16 <= simd_; x += 16) {
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(values + x),
                            interpolate16(src + x, window.image_step, w));
        const __m256i first = interpolateGradients8(dsrc + 2 * x, window.gradient_step, w);
        const __m256i second = interpolateGradients8(dsrc + 2 * x + 16, window.gradient_step, w);
        accumulateWide(first, q);
        accumulateWide(second, q);
        // Each block's pixels 0-3 in g0, 4-7 in g1: the first block low, the second high.
        const __m256i g0 = _mm256_permute2x128_si256(first, second, 0x20);
        const __m256i g1 = _mm256_permute2x128_si256(first, second, 0x31);
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(paired + 2 * x),
                            _mm256_unpacklo_epi16(g0, g1));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(paired + 2 * x + 16),
                            _mm256_unpackhi_epi16(g0, g1));
      }
      if (x < simd_) templateBlock(src, dsrc, x, window, w1, values, paired, q);
      if (tail_ > 0) templateTail(y, src, dsrc, window, w1, buf, tails);
    }
    *q_out = sums;
    *tails_out = tail_sums;
  }

  // mismatchRows two blocks at a time: each half's sums added in block order.
  ALVIO_AVX2 void mismatchRowsWide(const uchar* image, std::ptrdiff_t step_j, const Bilinear& w1,
                                   const Buffers& buf, __m128* qb0_out, __m128* qb1_out,
                                   float* ib1_out, float* ib2_out) const {
    __m128 b0 = *qb0_out, b1 = *qb1_out, *qb0 = &b0, *qb1 = &b1;
    float s1 = *ib1_out, s2 = *ib2_out, *ib1 = &s1, *ib2 = &s2;
    const Bilinear2 w = widen(w1);
    for (int y = 0; y < height_; ++y) {
      const uchar* src = image + y * step_j;
      const short* values = buf.values.data() + static_cast<std::ptrdiff_t>(y) * width_;
      const short* paired = buf.paired.data() + static_cast<std::ptrdiff_t>(y) * 2 * simd_;
      int x = 0;
      for (; x + 16 <= simd_; x += 16) {
        const __m256i diff =
            _mm256_sub_epi16(interpolate16(src + x, step_j, w), loadShorts(values + x));
        const __m256i d03 = _mm256_unpacklo_epi16(diff, diff);
        const __m256i d47 = _mm256_unpackhi_epi16(diff, diff);
        const __m256 lo = _mm256_cvtepi32_ps(
            _mm256_madd_epi16(_mm256_unpacklo_epi16(d03, d47), loadShorts(paired + 2 * x)));
        const __m256 hi = _mm256_cvtepi32_ps(
            _mm256_madd_epi16(_mm256_unpackhi_epi16(d03, d47), loadShorts(paired + 2 * x + 16)));
        *qb0 = _mm_add_ps(*qb0, _mm256_castps256_ps128(lo));
        *qb1 = _mm_add_ps(*qb1, _mm256_castps256_ps128(hi));
        *qb0 = _mm_add_ps(*qb0, _mm256_extractf128_ps(lo, 1));
        *qb1 = _mm_add_ps(*qb1, _mm256_extractf128_ps(hi, 1));
      }
      if (x < simd_) mismatchBlock(src, step_j, x, w1, values, paired, qb0, qb1);
      if (tail_ > 0) mismatchTail(y, src, step_j, w1, buf, ib1, ib2);
    }
    *qb0_out = b0;
    *qb1_out = b1;
    *ib1_out = s1;
    *ib2_out = s2;
  }
#endif

  const cv::Mat& I_;
  const cv::Mat& dI_;
  const cv::Mat& J_;
  int width_, height_, simd_, tail_;
  int level_, max_level_, max_iterations_;
  double epsilon_squared_;
  bool use_initial_flow_;
  bool wide_;  // two blocks at a time with AVX2
  const cv::Point2f* from_;
  cv::Point2f* to_;
  uchar* status_;
};

#endif  // __SSE2__

}  // namespace

void trackPyramidalKlt(const std::vector<cv::Mat>& from_pyramid,
                       const std::vector<cv::Mat>& to_pyramid, const std::vector<cv::Point2f>& from,
                       std::vector<cv::Point2f>* to, std::vector<uchar>* status, cv::Size window,
                       int max_level, const cv::TermCriteria& stop, bool use_initial_flow,
                       Vectors vectors) {
#if defined(__SSE2__)
  const bool supported = !from_pyramid.empty() && !to_pyramid.empty() && max_level >= 0 &&
                         window.width >= 8 && window.height > 2 &&
                         from_pyramid[0].type() == CV_8UC1 && to_pyramid[0].type() == CV_8UC1;
  const PyramidLayout from_layout = supported ? layoutOf(from_pyramid) : PyramidLayout();
  const PyramidLayout to_layout = supported ? layoutOf(to_pyramid) : PyramidLayout();
  if (!supported || from_layout.step != 2 || !padded(from_pyramid, from_layout, window) ||
      !padded(to_pyramid, to_layout, window) || (use_initial_flow && to->size() != from.size()))
    return openCvKlt(from_pyramid, to_pyramid, from, to, status, window, max_level, stop,
                     use_initial_flow);
  if (from.empty()) {
    to->clear();
    status->clear();
    return;
  }
  if (!use_initial_flow) to->resize(from.size());
  status->assign(from.size(), 1);
  max_level = std::min({max_level, from_layout.levels, to_layout.levels});
  const int max_iterations =
      (stop.type & cv::TermCriteria::COUNT) ? std::min(std::max(stop.maxCount, 0), 100) : 30;
  double epsilon =
      (stop.type & cv::TermCriteria::EPS) ? std::min(std::max(stop.epsilon, 0.), 10.) : 0.01;
  epsilon *= epsilon;
#if ALVIO_AVX2_CODE
  const bool wide = vectors == Vectors::kWidest && cpuHasAvx2();
#else
  const bool wide = false;
#endif
  for (int level = max_level; level >= 0; --level) {
    const LevelTracker tracker(from_pyramid[level * 2], from_pyramid[level * 2 + 1],
                               to_pyramid[level * to_layout.step], window, level, max_level,
                               max_iterations, epsilon, use_initial_flow, wide, from.data(),
                               to->data(), status->data());
    cv::parallel_for_(cv::Range(0, static_cast<int>(from.size())), tracker);
  }
#else
  (void)vectors;
  openCvKlt(from_pyramid, to_pyramid, from, to, status, window, max_level, stop, use_initial_flow);
#endif
}

}  // namespace alvio
