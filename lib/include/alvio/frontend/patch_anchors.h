#pragma once
// Anchored patch refinement of KLT point tracks. Frame-to-frame KLT adds a small error at
// every step, so a track's position drifts like a random walk (sim_MH_05: 0.51 px after 10
// frames, 1.1 px after 50), and the estimator, which compares every sighting with the
// track's first one in the window, takes that drift for independent noise. Here each track
// keeps the patch it had when it was anchored (its detection frame, renewed every
// `reanchor_frames`) and every new position is aligned to that patch: translation-only
// inverse-compositional Lucas-Kanade at full resolution, with the patch's brightness and
// contrast normalised, so that CLAHE's changing tone curve does not pull the alignment.
// The error along a track is then bounded by the alignment's, not summed over its steps.

#include <opencv2/core.hpp>
#include <unordered_map>
#include <vector>

namespace alvio {

struct PatchAnchorOptions {
  bool enabled = false;
  int window = 21;            ///< patch side (odd), pixels
  double max_shift_px = 1.0;  ///< refinements moving KLT's position further are not taken
  int reanchor_frames = 20;   ///< a track takes a new patch after this many frames (0: never)
  int max_iterations = 10;
  double min_zncc = 0.5;  ///< aligned patches correlating less are not taken
};

class PatchAnchors {
 public:
  explicit PatchAnchors(const PatchAnchorOptions& options);

  /// Takes the patch around `p` in the 8-bit `image` as track `id`'s anchor (replacing an
  /// older one). Returns false, and anchors nothing, where the patch leaves the image.
  bool anchor(int id, const cv::Mat& image, const cv::Point2f& p);
  /// Aligns track `id`'s anchored patch to `image`, starting at `*p`. Moves `*p` and returns
  /// true when the alignment converged within max_shift_px with at least min_zncc; leaves it
  /// otherwise. A track without an anchor is left as it is.
  bool refine(int id, const cv::Mat& image, cv::Point2f* p) const;
  /// One more frame for every track; returns whether `id` is due for a new anchor.
  bool dueForReanchor(int id) const;
  void tick();
  /// Forgets every track not in `ids`.
  void keepOnly(const std::vector<int>& ids);
  void clear() { patches_.clear(); }
  std::size_t size() const { return patches_.size(); }

 private:
  struct Patch {
    std::vector<float> values;          ///< zero-mean template, window x window, row-major
    std::vector<float> gx, gy;          ///< its gradients
    float norm = 0;                     ///< sqrt(sum of values^2)
    double sum_gx = 0, sum_gy = 0;      ///< sums of the gradients
    double sum_gx_t = 0, sum_gy_t = 0;  ///< sums of the gradients times the values
    double inv_h00 = 0, inv_h01 = 0, inv_h11 = 0;  ///< inverse of the 2x2 Gauss-Newton matrix
    int age = 0;                                   ///< frames since the patch was taken
  };
  PatchAnchorOptions options_;
  std::unordered_map<int, Patch> patches_;
};

}  // namespace alvio
