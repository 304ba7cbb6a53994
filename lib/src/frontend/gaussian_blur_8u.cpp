#include "alvio/frontend/gaussian_blur_8u.h"

#include <opencv2/imgproc.hpp>

#include "alvio/common/widest_vectors.h"

namespace alvio {

namespace {
// Every sum below is exact in 16 bits: the weights sum to 256, so a row's weighted sum of
// 8-bit pixels is at most 255 x 256, and each partial sum is smaller.

// One output row's vertical sums over rows[0 .. 2R] (row R the centre), each split into its
// high and low byte. w: the weights R .. 1 away, then the centre.
template <int R>
ALVIO_WIDEST_VECTORS void verticalSums(const std::uint8_t* const* rows, const std::uint16_t* w,
                                       int cols, std::uint8_t* __restrict high,
                                       std::uint8_t* __restrict low) {
  const std::uint8_t* r[2 * R + 1];
  for (int j = 0; j <= 2 * R; ++j) r[j] = rows[j];
  std::uint16_t k[R + 1];
  for (int j = 0; j <= R; ++j) k[j] = w[j];
  for (int x = 0; x < cols; ++x) {
    auto sum = static_cast<std::uint16_t>(k[R] * r[R][x]);
    for (int j = 0; j < R; ++j)
      sum = static_cast<std::uint16_t>(
          sum + k[j] * static_cast<std::uint16_t>(r[j][x] + r[2 * R - j][x]));
    high[x] = static_cast<std::uint8_t>(sum >> 8);
    low[x] = static_cast<std::uint8_t>(sum);
  }
}

// The horizontal sums of the vertical ones, from their high and low bytes (padded by R each
// side), rounded as OpenCV does: (256 H + L + 2^15) >> 16 = (H + 128 + (L >> 8)) >> 8.
template <int R>
ALVIO_WIDEST_VECTORS void horizontalSums(const std::uint8_t* high, const std::uint8_t* low,
                                         const std::uint16_t* w, int cols,
                                         std::uint8_t* __restrict out) {
  std::uint16_t k[R + 1];
  for (int j = 0; j <= R; ++j) k[j] = w[j];
  for (int x = 0; x < cols; ++x) {
    auto h = static_cast<std::uint16_t>(k[R] * high[x + R]);
    auto l = static_cast<std::uint16_t>(k[R] * low[x + R]);
    for (int j = 0; j < R; ++j) {
      h = static_cast<std::uint16_t>(
          h + k[j] * static_cast<std::uint16_t>(high[x + j] + high[x + 2 * R - j]));
      l = static_cast<std::uint16_t>(
          l + k[j] * static_cast<std::uint16_t>(low[x + j] + low[x + 2 * R - j]));
    }
    out[x] = static_cast<std::uint8_t>(static_cast<std::uint16_t>(h + 128 + (l >> 8)) >> 8);
  }
}

template <int R>
void blurRows(const cv::Mat& src, cv::Mat& dst, const std::uint16_t* w,
              std::vector<const std::uint8_t*>& rows, std::vector<std::uint8_t>& high,
              std::vector<std::uint8_t>& low) {
  const int cols = src.cols;
  for (int y = 0; y < src.rows; ++y) {
    for (int j = 0; j <= 2 * R; ++j)
      rows[j] = src.ptr(cv::borderInterpolate(y + j - R, src.rows, cv::BORDER_REFLECT_101));
    verticalSums<R>(rows.data(), w, cols, high.data() + R, low.data() + R);
    for (int b = 1; b <= R; ++b) {
      const int left = cv::borderInterpolate(-b, cols, cv::BORDER_REFLECT_101);
      const int right = cv::borderInterpolate(cols - 1 + b, cols, cv::BORDER_REFLECT_101);
      high[R - b] = high[R + left];
      low[R - b] = low[R + left];
      high[R + cols - 1 + b] = high[R + right];
      low[R + cols - 1 + b] = low[R + right];
    }
    horizontalSums<R>(high.data(), low.data(), w, cols, dst.ptr(y));
  }
}

// The weights OpenCV blurs with, from its blur of a vertical line of 255 on 0: there the
// vertical sum is 255 x 256 everywhere on the line, so pixel i off the line becomes
// round(255 w_i / 256) = w_i while w_i <= 128. Empty where the weights do not read back as a
// symmetric kernel summing to 256.
std::vector<std::uint16_t> readOpenCvWeights(int ksize, double sigma) {
  const int side = 2 * ksize + 1, centre = ksize, half = ksize / 2;
  cv::Mat line(side, side, CV_8UC1, cv::Scalar(0)), blurred;
  line.col(centre).setTo(255);
  cv::GaussianBlur(line, blurred, cv::Size(ksize, ksize), sigma);
  std::vector<std::uint16_t> weights(ksize);
  int sum = 0;
  for (int i = 0; i < ksize; ++i) {
    weights[i] = blurred.at<std::uint8_t>(centre, centre - half + i);
    sum += weights[i];
  }
  for (int i = 0; i < ksize; ++i)
    if (weights[i] != weights[ksize - 1 - i] || weights[i] > 128) return {};
  if (sum != 256) return {};
  return weights;
}
}  // namespace

GaussianBlur8u::GaussianBlur8u(int ksize, double sigma) : ksize_(ksize), sigma_(sigma) {
  CV_Assert(ksize > 0 && ksize % 2 == 1);
  const std::vector<std::uint16_t> weights = readOpenCvWeights(ksize, sigma);
  if (weights.empty()) return;
  const int half = ksize / 2;
  int radius = half;
  while (radius > 0 && weights[half - radius] == 0) --radius;  // zero weights add nothing
  if (radius == 0 || radius > kMaxRadius) return;
  for (int j = 0; j <= radius; ++j) half_kernel_.push_back(weights[half - radius + j]);
  radius_ = radius;
  // Checked once against OpenCV, borders included: any doubt, and OpenCV blurs.
  cv::RNG rng(7);
  cv::Mat probe(ksize + 26, ksize + 34, CV_8UC1), expected, got;
  rng.fill(probe, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(probe, expected, cv::Size(ksize, ksize), sigma);
  apply(probe, got);
  if (cv::countNonZero(got != expected) != 0) {
    radius_ = 0;
    half_kernel_.clear();
  }
}

void GaussianBlur8u::apply(const cv::Mat& src, cv::Mat& dst) {
  CV_Assert(src.type() == CV_8UC1);
  // Images narrower or shorter than the kernel, and views into larger images (whose border
  // OpenCV takes from the pixels around them): OpenCV's border code, not this one.
  if (radius_ == 0 || src.rows < ksize_ || src.cols < ksize_ || src.isSubmatrix() ||
      src.data == dst.data) {
    cv::GaussianBlur(src, dst, cv::Size(ksize_, ksize_), sigma_);
    return;
  }
  dst.create(src.size(), CV_8UC1);
  rows_.resize(2 * radius_ + 1);
  high_.resize(src.cols + 2 * radius_);
  low_.resize(src.cols + 2 * radius_);
  const std::uint16_t* w = half_kernel_.data();
  switch (radius_) {
    case 1:
      blurRows<1>(src, dst, w, rows_, high_, low_);
      break;
    case 2:
      blurRows<2>(src, dst, w, rows_, high_, low_);
      break;
    case 3:
      blurRows<3>(src, dst, w, rows_, high_, low_);
      break;
    case 4:
      blurRows<4>(src, dst, w, rows_, high_, low_);
      break;
    case 5:
      blurRows<5>(src, dst, w, rows_, high_, low_);
      break;
    default:
      blurRows<6>(src, dst, w, rows_, high_, low_);
      break;
  }
}

}  // namespace alvio
