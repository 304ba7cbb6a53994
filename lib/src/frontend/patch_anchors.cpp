#include "alvio/frontend/patch_anchors.h"

#include <algorithm>
#include <cmath>
#include <unordered_set>

namespace alvio {
namespace {

// Bilinear samples of the side x side grid (unit steps) centred on p. All samples share p's
// fractional part, so the four weights are computed once. False where the grid (and the
// pixel right and below each sample) leaves the image.
bool samplePatch(const cv::Mat& image, const cv::Point2f& p, int side, float* out) {
  const int h = side / 2;
  const float x0 = p.x - h, y0 = p.y - h;
  if (!(x0 >= 0.f && y0 >= 0.f)) return false;  // also NaN
  const int ix = static_cast<int>(x0), iy = static_cast<int>(y0);
  if (ix + side >= image.cols || iy + side >= image.rows) return false;
  const float fx = x0 - ix, fy = y0 - iy;
  const float w00 = (1 - fx) * (1 - fy), w01 = fx * (1 - fy), w10 = (1 - fx) * fy, w11 = fx * fy;
  for (int r = 0; r < side; ++r) {
    const uchar* a = image.ptr<uchar>(iy + r) + ix;
    const uchar* b = image.ptr<uchar>(iy + r + 1) + ix;
    for (int c = 0; c < side; ++c)
      *out++ = w00 * a[c] + w01 * a[c + 1] + w10 * b[c] + w11 * b[c + 1];
  }
  return true;
}

}  // namespace

PatchAnchors::PatchAnchors(const PatchAnchorOptions& options) : options_(options) {}

bool PatchAnchors::anchor(int id, const cv::Mat& image, const cv::Point2f& p) {
  const int n = options_.window, m = n + 2;  // one pixel more each side for the gradients
  std::vector<float> big(m * m);
  if (!samplePatch(image, p, m, big.data())) return false;
  Patch patch;
  patch.values.resize(n * n);
  patch.gx.resize(n * n);
  patch.gy.resize(n * n);
  double sum = 0;
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const int k = r * n + c, b = (r + 1) * m + (c + 1);
      patch.values[k] = big[b];
      patch.gx[k] = 0.5f * (big[b + 1] - big[b - 1]);
      patch.gy[k] = 0.5f * (big[b + m] - big[b - m]);
      sum += big[b];
    }
  const float mean = static_cast<float>(sum / (n * n));
  double h00 = 0, h01 = 0, h11 = 0, ss = 0;
  for (int k = 0; k < n * n; ++k) {
    patch.values[k] -= mean;
    ss += patch.values[k] * patch.values[k];
    h00 += patch.gx[k] * patch.gx[k];
    h01 += patch.gx[k] * patch.gy[k];
    h11 += patch.gy[k] * patch.gy[k];
  }
  const double det = h00 * h11 - h01 * h01;
  if (!(det > 1e-6 * (h00 + h11) * (h00 + h11)) || ss <= 0) return false;  // no 2D texture
  patch.inv_h00 = h11 / det;
  patch.inv_h01 = -h01 / det;
  patch.inv_h11 = h00 / det;
  patch.norm = static_cast<float>(std::sqrt(ss));
  for (int k = 0; k < n * n; ++k) {
    patch.sum_gx += patch.gx[k];
    patch.sum_gy += patch.gy[k];
    patch.sum_gx_t += patch.gx[k] * patch.values[k];
    patch.sum_gy_t += patch.gy[k] * patch.values[k];
  }
  patches_[id] = std::move(patch);
  return true;
}

bool PatchAnchors::refine(int id, const cv::Mat& image, cv::Point2f* p) const {
  const auto it = patches_.find(id);
  if (it == patches_.end()) return false;
  const Patch& t = it->second;
  const int n = options_.window, h = n / 2, count = n * n;
  cv::Point2f q = *p;
  bool converged = false;
  double zncc = 0;
  for (int iter = 0; iter < options_.max_iterations; ++iter) {
    // One pass over the image patch at q gathers every sum the step needs; the error image
    // (the patch scaled to the template's contrast, minus the template) is never formed:
    //   e = gain (I - mean) - T,  sum g e = gain (sum g I - mean sum g) - sum g T.
    const float x0 = q.x - h, y0 = q.y - h;
    if (!(x0 >= 0.f && y0 >= 0.f)) return false;  // also NaN
    const int ix = static_cast<int>(x0), iy = static_cast<int>(y0);
    if (ix + n >= image.cols || iy + n >= image.rows) return false;
    const float fx = x0 - ix, fy = y0 - iy;
    const float w00 = (1 - fx) * (1 - fy), w01 = fx * (1 - fy), w10 = (1 - fx) * fy, w11 = fx * fy;
    float s1 = 0, s2 = 0, st = 0, sgx = 0, sgy = 0;
    for (int r = 0; r < n; ++r) {
      const uchar* a = image.ptr<uchar>(iy + r) + ix;
      const uchar* b = image.ptr<uchar>(iy + r + 1) + ix;
      const float* tv = t.values.data() + r * n;
      const float* gx = t.gx.data() + r * n;
      const float* gy = t.gy.data() + r * n;
      for (int c = 0; c < n; ++c) {
        const float v = w00 * a[c] + w01 * a[c + 1] + w10 * b[c] + w11 * b[c + 1];
        s1 += v;
        s2 += v * v;
        st += v * tv[c];
        sgx += v * gx[c];
        sgy += v * gy[c];
      }
    }
    const double mean = s1 / count;
    const double ss = s2 - count * mean * mean;
    if (!(ss > 0)) return false;
    zncc = st / (std::sqrt(ss) * t.norm);  // the template has zero mean
    const double gain = t.norm / std::sqrt(ss);
    const double bx = gain * (sgx - mean * t.sum_gx) - t.sum_gx_t;
    const double by = gain * (sgy - mean * t.sum_gy) - t.sum_gy_t;
    // Inverse compositional: the template's step, applied inverted to the image position.
    const double dx = t.inv_h00 * bx + t.inv_h01 * by;
    const double dy = t.inv_h01 * bx + t.inv_h11 * by;
    q.x -= static_cast<float>(dx);
    q.y -= static_cast<float>(dy);
    if (dx * dx + dy * dy < 1e-4) {
      converged = true;
      break;
    }
  }
  const float sx = q.x - p->x, sy = q.y - p->y;
  if (!converged || zncc < options_.min_zncc ||
      sx * sx + sy * sy > options_.max_shift_px * options_.max_shift_px)
    return false;
  *p = q;
  return true;
}

bool PatchAnchors::dueForReanchor(int id) const {
  if (options_.reanchor_frames <= 0) return false;
  const auto it = patches_.find(id);
  return it == patches_.end() || it->second.age >= options_.reanchor_frames;
}

void PatchAnchors::tick() {
  for (auto& [id, patch] : patches_) ++patch.age;
}

void PatchAnchors::keepOnly(const std::vector<int>& ids) {
  const std::unordered_set<int> keep(ids.begin(), ids.end());
  for (auto it = patches_.begin(); it != patches_.end();)
    it = keep.count(it->first) ? std::next(it) : patches_.erase(it);
}

}  // namespace alvio
