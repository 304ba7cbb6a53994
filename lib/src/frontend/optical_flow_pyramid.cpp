#include "alvio/frontend/optical_flow_pyramid.h"

#include <cstring>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "alvio/common/widest_vectors.h"

namespace alvio {
namespace {

// One row of OpenCV's Scharr gradients (cv::detail::ScharrDerivInvoker): the vertical
// [3 10 3] and [-1 0 1] passes into `smooth` and `diff` (cols + 2 entries, one of border at
// each end), then the horizontal ones, interleaved (dx, dy) into `out`. All in 16 bits: the
// sums stay within +-4080.
ALVIO_WIDEST_VECTORS
void scharrRow(const uchar* above, const uchar* row, const uchar* below, int cols,
               short* __restrict smooth, short* __restrict diff, short* __restrict out) {
  short* s = smooth + 1;
  short* d = diff + 1;
  for (int x = 0; x < cols; ++x) {
    s[x] = static_cast<short>((above[x] + below[x]) * 3 + row[x] * 10);
    d[x] = static_cast<short>(below[x] - above[x]);
  }
  // Reflect-101 at the row's ends, as OpenCV.
  const int x0 = cols > 1 ? 1 : 0, x1 = cols > 1 ? cols - 2 : 0;
  s[-1] = s[x0];
  s[cols] = s[x1];
  d[-1] = d[x0];
  d[cols] = d[x1];
  for (int x = 0; x < cols; ++x) {
    out[2 * x] = static_cast<short>(s[x + 1] - s[x - 1]);
    out[2 * x + 1] = static_cast<short>((d[x + 1] + d[x - 1]) * 3 + d[x] * 10);
  }
}

// A zero border of `border` around the centre `size` of a CV_16SC2 buffer.
void zeroBorder(cv::Mat& whole, cv::Size border, cv::Size size) {
  const std::size_t row_bytes = whole.cols * whole.elemSize();
  for (int y = 0; y < border.height; ++y) {
    std::memset(whole.ptr(y), 0, row_bytes);
    std::memset(whole.ptr(border.height + size.height + y), 0, row_bytes);
  }
  const std::size_t side_bytes = border.width * whole.elemSize();
  for (int y = border.height; y < border.height + size.height; ++y) {
    std::memset(whole.ptr(y), 0, side_bytes);
    std::memset(whole.ptr(y) + (border.width + size.width) * whole.elemSize(), 0, side_bytes);
  }
}

// The reflect-101 border of `border` around the centre `size` of an 8-bit buffer. Levels above
// the first are larger than the window, so one reflection reaches every border pixel.
void reflectBorder(cv::Mat& whole, cv::Size border, cv::Size size) {
  const int bw = border.width, bh = border.height;
  for (int y = bh; y < bh + size.height; ++y) {
    uchar* r = whole.ptr(y);
    const int first = bw, last = bw + size.width - 1;
    for (int k = 1; k <= bw; ++k) {
      r[first - k] = r[first + k];
      r[last + k] = r[last - k];
    }
  }
  const std::size_t row_bytes = whole.cols;
  const int top = bh, bottom = bh + size.height - 1;
  for (int k = 1; k <= bh; ++k) {
    std::memcpy(whole.ptr(top - k), whole.ptr(top + k), row_bytes);
    std::memcpy(whole.ptr(bottom + k), whole.ptr(bottom - k), row_bytes);
  }
}

cv::Mat parentOf(const cv::Mat& centre, cv::Size border) {
  cv::Mat whole = centre;
  whole.adjustROI(border.height, border.height, border.width, border.width);
  return whole;
}

// The centre `size` of a buffer with a border of `border`: `old`'s when it is such a view and
// nothing else holds its buffer (an older pyramid handed back), otherwise a new buffer.
cv::Mat bordered(const cv::Mat& old, cv::Size size, cv::Size border, int type) {
  if (old.size() == size && old.type() == type && old.u != nullptr && old.u->refcount == 1) {
    cv::Size whole;
    cv::Point offset;
    old.locateROI(whole, offset);
    if (offset == cv::Point(border.width, border.height) &&
        whole == cv::Size(size.width + 2 * border.width, size.height + 2 * border.height))
      return old;
  }
  cv::Mat whole(size.height + 2 * border.height, size.width + 2 * border.width, type);
  return whole(cv::Rect(border.width, border.height, size.width, size.height));
}

}  // namespace

void scharrGradients(const cv::Mat& image, cv::Mat& gradients) {
  CV_Assert(image.type() == CV_8UC1 && gradients.type() == CV_16SC2 &&
            gradients.size() == image.size());
  const int rows = image.rows, cols = image.cols;
  std::vector<short> smooth(cols + 2), diff(cols + 2);
  for (int y = 0; y < rows; ++y) {
    const int above = y > 0 ? y - 1 : (rows > 1 ? 1 : 0);
    const int below = y < rows - 1 ? y + 1 : (rows > 1 ? rows - 2 : 0);
    scharrRow(image.ptr(above), image.ptr(y), image.ptr(below), cols, smooth.data(), diff.data(),
              gradients.ptr<short>(y));
  }
}

int buildOpticalFlowPyramid8u(const cv::Mat& image, cv::Size window, int max_level,
                              std::vector<cv::Mat>* pyramid) {
  if (image.type() != CV_8UC1 || window.width <= 2 || window.height <= 2 || max_level < 0)
    return cv::buildOpticalFlowPyramid(image, *pyramid, window, max_level, true,
                                       cv::BORDER_REFLECT_101, cv::BORDER_CONSTANT, false);
  pyramid->resize(2 * (max_level + 1));
  cv::Size size = image.size();
  for (int level = 0; level <= max_level; ++level) {
    cv::Mat& img = (*pyramid)[2 * level];
    img = bordered(img, size, window, CV_8UC1);
    cv::Mat img_whole = parentOf(img, window);
    if (level == 0) {
      // As OpenCV: a view into a larger image takes its border from the pixels around it.
      cv::copyMakeBorder(image, img_whole, window.height, window.height, window.width, window.width,
                         cv::BORDER_REFLECT_101);
    } else {
      cv::pyrDown((*pyramid)[2 * level - 2], img, size);
      reflectBorder(img_whole, window, size);
    }

    cv::Mat& gradients = (*pyramid)[2 * level + 1];
    gradients = bordered(gradients, size, window, CV_16SC2);
    scharrGradients(img, gradients);
    cv::Mat gradients_whole = parentOf(gradients, window);
    zeroBorder(gradients_whole, window, size);

    // As OpenCV: no level as small as the window.
    size = cv::Size((size.width + 1) / 2, (size.height + 1) / 2);
    if (size.width <= window.width || size.height <= window.height) {
      pyramid->resize(2 * (level + 1));
      return level;
    }
  }
  return max_level;
}

}  // namespace alvio
