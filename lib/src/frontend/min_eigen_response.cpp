#include "alvio/frontend/min_eigen_response.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "alvio/common/widest_vectors.h"

namespace alvio {

namespace {
// Reflect-101 (OpenCV's default border): -1 -> 1, n -> n - 2.
int reflect101(int i, int n) {
  return i < 0 ? -i : (i >= n ? 2 * n - 2 - i : i);
}

// Fill the one-pixel pads of a row of w values stored from index 1.
inline void padReflect101(int32_t* row, int w) {
  row[0] = row[2];
  row[w + 1] = row[w - 1];
}

// o = u + v + t, element-wise; restrict lets the compiler vectorise it.
ALVIO_WIDEST_VECTORS
void addRows(const int32_t* __restrict u, const int32_t* __restrict v, const int32_t* __restrict t,
             int32_t* __restrict o, int n) {
  for (int x = 0; x < n; ++x) o[x] = u[x] + v[x] + t[x];
}

// Sobel 3x3, separable: [1 2 1] down the columns then [-1 0 1] along the row for x, and
// [-1 0 1] down then [1 2 1] along for y; then the gradient products. `s` and `d` have a
// one-pixel pad at each end.
ALVIO_WIDEST_VECTORS
void sobelProducts(const uchar* __restrict up, const uchar* __restrict mid,
                   const uchar* __restrict down, int w, int32_t* __restrict s,
                   int32_t* __restrict d, int32_t* __restrict xx, int32_t* __restrict xy,
                   int32_t* __restrict yy) {
  for (int x = 0; x < w; ++x) {
    s[x + 1] = up[x] + 2 * mid[x] + down[x];
    d[x + 1] = down[x] - up[x];
  }
  padReflect101(s, w);
  padReflect101(d, w);
  for (int x = 0; x < w; ++x) {
    const int32_t gx = s[x + 2] - s[x];
    const int32_t gy = d[x] + 2 * d[x + 1] + d[x + 2];
    xx[x] = gx * gx;  // |g| <= 1020: sums of nine products stay below 2^24, exact as floats
    xy[x] = gx * gy;
    yy[x] = gy * gy;
  }
}

// The smaller eigenvalue of each pixel's summed structure tensor, from the rows' 3-sums
// (one-pixel pads at each end).
ALVIO_WIDEST_VECTORS
void minEigenRow(const int32_t* __restrict sxx, const int32_t* __restrict sxy,
                 const int32_t* __restrict syy, int w, float half_scale2, float* __restrict out) {
  for (int x = 0; x < w; ++x) {
    const float a = static_cast<float>(sxx[x] + sxx[x + 1] + sxx[x + 2]);
    const float b = static_cast<float>(sxy[x] + sxy[x + 1] + sxy[x + 2]);
    const float c = static_cast<float>(syy[x] + syy[x + 1] + syy[x + 2]);
    // Needs -fno-math-errno to vectorise (CMakeLists.txt sets it for this file).
    out[x] = half_scale2 * ((a + c) - std::sqrt((a - c) * (a - c) + 4.0f * b * b));
  }
}
}  // namespace

void MinEigenResponse::productRow(const cv::Mat& image, int y, int slot) {
  const int w = image.cols, h = image.rows;
  int32_t* products = products_.data() + 3 * slot * w;
  sobelProducts(image.ptr<uchar>(reflect101(y - 1, h)), image.ptr<uchar>(y),
                image.ptr<uchar>(reflect101(y + 1, h)), w, smooth_.data(), diff_.data(), products,
                products + w, products + 2 * w);
  product_rows_[slot] = y;
}

void MinEigenResponse::compute(const cv::Mat& image, cv::Mat* response) {
  CV_Assert(image.type() == CV_8UC1);
  const int w = image.cols, h = image.rows;
  if (w < 3 || h < 3) {
    cv::cornerMinEigenVal(image, *response, 3, 3);
    return;
  }
  response->create(image.size(), CV_32F);
  products_.resize(9 * static_cast<std::size_t>(w));
  for (auto* row : {&smooth_, &diff_, &sum_xx_, &sum_xy_, &sum_yy_}) row->resize(w + 2);
  for (int& r : product_rows_) r = -1;
  auto slotFor = [&](int y) {
    const int slot = y % 3;
    if (product_rows_[slot] != y) productRow(image, y, slot);
    return slot;
  };
  // OpenCV's scale: 1 / (2^(aperture - 1) * block * 255) per derivative; its eigenvalue
  // formula halves the diagonal sums.
  const double scale = 1.0 / (4.0 * 3.0 * 255.0);
  const float half_scale2 = static_cast<float>(0.5 * scale * scale);
  for (int y = 0; y < h; ++y) {
    const int32_t* rows[3] = {products_.data() + 3 * w * slotFor(reflect101(y - 1, h)),
                              products_.data() + 3 * w * slotFor(y),
                              products_.data() + 3 * w * slotFor(reflect101(y + 1, h))};
    int32_t* sums[3] = {sum_xx_.data() + 1, sum_xy_.data() + 1, sum_yy_.data() + 1};
    for (int k = 0; k < 3; ++k)
      addRows(rows[0] + k * w, rows[1] + k * w, rows[2] + k * w, sums[k], w);
    padReflect101(sum_xx_.data(), w);
    padReflect101(sum_xy_.data(), w);
    padReflect101(sum_yy_.data(), w);
    minEigenRow(sum_xx_.data(), sum_xy_.data(), sum_yy_.data(), w, half_scale2,
                response->ptr<float>(y));
  }
}

}  // namespace alvio
