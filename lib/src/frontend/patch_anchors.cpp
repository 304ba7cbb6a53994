#include "alvio/frontend/patch_anchors.h"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <type_traits>
#include <unordered_set>

#include "alvio/frontend/warped_patch_sums.h"

namespace alvio {
namespace {

// An alignment has converged when its shift step is under 0.03 px (squared here): far below
// the tracks' noise (0.2-0.3 px), and half the iterations of a 0.01 px limit.
constexpr double kConvergedStep2 = 0.03 * 0.03;

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

// The upper triangle of g g^T (K x K, row by row) added to `upper`.
constexpr int kUpperSize = 21;  // 6 x 6
template <int K>
void addOuterUpper(const double* g, double* upper) {
  int t = 0;
  for (int i = 0; i < K; ++i)
    for (int j = i; j < K; ++j) upper[t++] += g[i] * g[j];
}

}  // namespace

PatchAnchors::PatchAnchors(const PatchAnchorOptions& options)
    : options_(options), k_params_(warpParameters(options.warp)) {}

int PatchAnchors::warpParameters(const std::string& warp) {
  if (warp == "similarity") return 4;
  if (warp == "affine") return 6;
  return 2;
}

bool PatchAnchors::anchor(int id, const cv::Mat& image, const cv::Point2f& p) {
  const int n = options_.window, m = n + 2, h = n / 2;  // one more pixel each side: gradients
  const bool affine = k_params_ == 6;
  std::vector<float>& big = scratch_big_;
  big.resize(m * m);
  if (!samplePatch(image, p, m, big.data())) return false;
  Patch patch;
  // The warps keep only the packed blocks: the values and sd are then worked out in buffers
  // kept from call to call.
  std::vector<float>& values = k_params_ > 2 ? scratch_values_ : patch.values;
  std::array<std::vector<float>, 6>& sd = k_params_ > 2 ? scratch_sd_ : patch.sd;
  values.resize(n * n);
  for (int i = 0; i < k_params_; ++i) sd[i].resize(n * n);
  double sum = 0;
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const int k = r * n + c, b = (r + 1) * m + (c + 1);
      const float gx = 0.5f * (big[b + 1] - big[b - 1]), gy = 0.5f * (big[b + m] - big[b - m]);
      const float x = static_cast<float>(c - h), y = static_cast<float>(r - h);
      values[k] = big[b];
      sd[0][k] = gx;
      sd[1][k] = gy;
      if (k_params_ == 4) {
        sd[2][k] = gx * x + gy * y;   // scale
        sd[3][k] = -gx * y + gy * x;  // rotation
      } else if (affine) {            // A = I + [p2 p3; p4 p5]
        sd[2][k] = gx * x;
        sd[3][k] = gx * y;
        sd[4][k] = gy * x;
        sd[5][k] = gy * y;
      }
      sum += big[b];
    }
  const float mean = static_cast<float>(sum / (n * n));
  double ss = 0;
  // The normal matrix's upper triangle, mirrored after: each entry sums the same products in
  // the same order as the whole outer product g g^T, in about half the work.
  double upper[kUpperSize] = {};
  patch.sum_sd.setZero();
  patch.sum_sd_t.setZero();
  // One loop per parameter count, so that the outer product is inlined with its sums kept in
  // registers.
  const auto accumulate = [&](auto parameters) {
    constexpr int K = decltype(parameters)::value;
    for (int k = 0; k < n * n; ++k) {
      values[k] -= mean;
      ss += values[k] * values[k];
      Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
      for (int i = 0; i < K; ++i) g[i] = sd[i][k];
      addOuterUpper<K>(g.data(), upper);
      patch.sum_sd += g;
      patch.sum_sd_t += g * values[k];
    }
  };
  if (k_params_ == 6)
    accumulate(std::integral_constant<int, 6>());
  else if (k_params_ == 4)
    accumulate(std::integral_constant<int, 4>());
  else
    accumulate(std::integral_constant<int, 2>());
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  for (int i = 0, t = 0; i < k_params_; ++i)
    for (int j = i; j < k_params_; ++j, ++t) H(i, j) = H(j, i) = upper[t];
  const Eigen::Matrix2d H2 = H.topLeftCorner<2, 2>();
  const double trace = H2.trace();
  if (!(H2.determinant() > 1e-6 * trace * trace) || ss <= 0) return false;  // no 2D texture
  patch.inv_h2 = H2.inverse();
  if (k_params_ > 2) {
    // The linear part is weakly seen on plain patches: a small ridge keeps the system
    // invertible there, and barely touches textured ones.
    const int l = k_params_ - 2;
    const double ridge = 1e-3 * H.diagonal().segment(2, l).sum() / l + 1e-9;
    H.diagonal().segment(2, l).array() += ridge;
    patch.inv_h.setZero();
    patch.inv_h.topLeftCorner(k_params_, k_params_) =
        H.topLeftCorner(k_params_, k_params_).inverse();
  }
  patch.norm = static_cast<float>(std::sqrt(ss));
  if (k_params_ > 2) {
    // A track's new patch takes its old patch's buffer.
    if (const auto it = patches_.find(id); it != patches_.end())
      patch.packed.swap(it->second.packed);
    patch.packed.assign(std::size_t(n) * n * 8, 0.0f);
    for (int k = 0; k < n * n; ++k) {
      float* block = &patch.packed[std::size_t(k) * 8];
      block[0] = 1.0f;
      block[1] = values[k];
      for (int i = 0; i < k_params_; ++i) block[2 + i] = sd[i][k];
    }
  }
  patches_[id] = std::move(patch);
  return true;
}

Alignment PatchAnchors::refine(int id, const cv::Mat& image, cv::Point2f* p) {
  const auto it = patches_.find(id);
  if (it == patches_.end()) return Alignment::kNoAnchor;
  Patch& t = it->second;
  const Alignment a = k_params_ == 2 ? refineShift(t, image, p) : refineWarp(t, image, p);
  if (a == Alignment::kAligned) t.confirmed = true;
  if (a == Alignment::kMismatch && !t.confirmed) return Alignment::kUnconfirmed;
  return a;
}

Alignment PatchAnchors::refineShift(Patch& t, const cv::Mat& image, cv::Point2f* p) const {
  const int n = options_.window, h = n / 2, count = n * n;
  cv::Point2f q = *p;
  bool converged = false;
  double zncc = 0;
  for (int iter = 0; iter < options_.max_iterations; ++iter) {
    // One pass over the image patch at q gathers every sum the step needs; the error image
    // (the patch scaled to the template's contrast, minus the template) is never formed:
    //   e = gain (I - mean) - T,  sum g e = gain (sum g I - mean sum g) - sum g T.
    const float x0 = q.x - h, y0 = q.y - h;
    if (!(x0 >= 0.f && y0 >= 0.f)) return Alignment::kOutside;  // also NaN
    const int ix = static_cast<int>(x0), iy = static_cast<int>(y0);
    if (ix + n >= image.cols || iy + n >= image.rows) return Alignment::kOutside;
    const float fx = x0 - ix, fy = y0 - iy;
    const float w00 = (1 - fx) * (1 - fy), w01 = fx * (1 - fy), w10 = (1 - fx) * fy, w11 = fx * fy;
    float s1 = 0, s2 = 0, st = 0, sgx = 0, sgy = 0;
    for (int r = 0; r < n; ++r) {
      const uchar* a = image.ptr<uchar>(iy + r) + ix;
      const uchar* b = image.ptr<uchar>(iy + r + 1) + ix;
      const float* tv = t.values.data() + r * n;
      const float* gx = t.sd[0].data() + r * n;
      const float* gy = t.sd[1].data() + r * n;
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
    if (!(ss > 0)) return Alignment::kMismatch;
    zncc = st / (std::sqrt(ss) * t.norm);  // the template has zero mean
    const double gain = t.norm / std::sqrt(ss);
    const Eigen::Vector2d g(gain * (sgx - mean * t.sum_sd[0]) - t.sum_sd_t[0],
                            gain * (sgy - mean * t.sum_sd[1]) - t.sum_sd_t[1]);
    // Inverse compositional: the template's step, applied inverted to the image position.
    const Eigen::Vector2d d = t.inv_h2 * g;
    q.x -= static_cast<float>(d.x());
    q.y -= static_cast<float>(d.y());
    if (d.squaredNorm() < kConvergedStep2) {
      converged = true;
      break;
    }
  }
  const float sx = q.x - p->x, sy = q.y - p->y;
  if (!converged || zncc < options_.min_zncc ||
      sx * sx + sy * sy > options_.max_shift_px * options_.max_shift_px)
    return Alignment::kMismatch;
  *p = q;
  return Alignment::kAligned;
}

namespace {
// The linear part of a warp step d (similarity: scale, rotation; affine: four entries).
Eigen::Matrix2d linearStep(const Eigen::Matrix<double, 6, 1>& d, int k_params) {
  if (k_params == 4) return (Eigen::Matrix2d() << 1 + d[2], -d[3], d[3], 1 + d[2]).finished();
  return (Eigen::Matrix2d() << 1 + d[2], d[3], d[4], 1 + d[5]).finished();
}
}  // namespace

Alignment PatchAnchors::refineWarp(Patch& t, const cv::Mat& image, cv::Point2f* p) const {
  const int n = options_.window, h = n / 2, count = n * n;
  // It starts at KLT's position with the linear part the track had last.
  Eigen::Matrix2d A = t.A;
  double qx = p->x, qy = p->y;
  bool converged = false;
  double zncc = 0;
  for (int iter = 0; iter < options_.max_iterations; ++iter) {
    // The warped window's corners bound it: all must leave room for the bilinear neighbour.
    bool inside = true;
    for (int cy : {-h, h})
      for (int cx : {-h, h}) {
        const double u = qx + A(0, 0) * cx + A(0, 1) * cy, v = qy + A(1, 0) * cx + A(1, 1) * cy;
        inside &= u >= 0 && v >= 0 && u < image.cols - 1.01 && v < image.rows - 1.01;
      }
    if (!inside) return Alignment::kOutside;  // also NaN
    float s2 = 0, sums[8];
    // `packed` holds per pixel {1, value, sd[0..5]}: sums[0] is the samples' sum, sums[1]
    // their product with the template, sums[2..7] with the steepest-descent images.
    warpedPatchSums(image, A, qx, qy, n, t.packed.data(), &s2, sums);
    const float s1 = sums[0], st = sums[1];
    const float* sg = sums + 2;
    const double mean = s1 / count;
    const double ss = s2 - count * mean * mean;
    if (!(ss > 0)) return Alignment::kMismatch;
    zncc = st / (std::sqrt(ss) * t.norm);
    const double gain = t.norm / std::sqrt(ss);
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    for (int i = 0; i < k_params_; ++i) g[i] = gain * (sg[i] - mean * t.sum_sd[i]) - t.sum_sd_t[i];
    const Eigen::Matrix<double, 6, 1> d = t.inv_h * g;
    // Inverse compositional update: W <- W o W(d)^-1, with W(d) = A_d x + d_shift.
    const Eigen::Matrix2d A_new = A * linearStep(d, k_params_).inverse();
    const Eigen::Vector2d q_new = Eigen::Vector2d(qx, qy) - A_new * d.head<2>();
    qx = q_new.x();
    qy = q_new.y();
    A = A_new;
    // The linear part need not settle here: it changes slowly, and each frame's alignment
    // starts from the last one's.
    if (d.head<2>().squaredNorm() < kConvergedStep2) {
      converged = true;
      break;
    }
  }
  const double sx = qx - p->x, sy = qy - p->y;
  // A warp far from a rigid motion's is a wrong alignment, not a track seen much nearer.
  const Eigen::JacobiSVD<Eigen::Matrix2d> svd(A);
  const double s_max = svd.singularValues()[0], s_min = svd.singularValues()[1];
  if (!converged || zncc < options_.min_zncc || s_max > 1.4 || s_min < 0.7 ||
      sx * sx + sy * sy > options_.max_shift_px * options_.max_shift_px)
    return Alignment::kMismatch;
  p->x = static_cast<float>(qx);
  p->y = static_cast<float>(qy);
  t.A = A;
  return Alignment::kAligned;
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
