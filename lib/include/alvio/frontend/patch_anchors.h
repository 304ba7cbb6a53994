#pragma once
// Anchored patch refinement of KLT point tracks. Frame-to-frame KLT adds a small error at
// every step, so a track's position drifts like a random walk (sim_MH_05: 0.51 px after 10
// frames, 1.1 px after 50), and the estimator, which compares every sighting with the
// track's first one in the window, takes that drift for independent noise. Here each track
// keeps the patch it had when it was anchored (its detection frame, renewed every
// `reanchor_frames` if set) and every new position is aligned to that patch:
// inverse-compositional Lucas-Kanade at full resolution, with the patch's brightness and
// contrast normalised, so that CLAHE's changing tone curve does not pull the alignment. The
// warp is a shift, a similarity or an affine map (its last linear part carried from frame to
// frame), so that a patch seen nearer or slanted is not pulled towards its strongest edges.
// The error along a track is then bounded by the alignment's, not summed over its steps.

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <string>
#include <unordered_map>
#include <vector>

namespace alvio {

/// What became of an alignment.
enum class Alignment {
  kAligned,   ///< converged within max_shift_px and min_zncc: the position was moved
  kNoAnchor,  ///< the track has no patch
  kOutside,   ///< the patch reaches out of the image
  kMismatch,  ///< no convergence, too far, too little correlation, or an implausible warp
  /// A mismatch of a patch that has never aligned since it was taken: mostly a corner whose
  /// texture is near the noise (a plain wall under CLAHE correlates 0.0-0.2 one frame
  /// later), which tells nothing about the track, unlike a confirmed patch that stops fitting.
  kUnconfirmed,
};

struct PatchAnchorOptions {
  bool enabled = true;
  int window = 21;            ///< patch side (odd), pixels
  double max_shift_px = 1.0;  ///< refinements moving KLT's position further are not taken
  int reanchor_frames = 0;    ///< a track takes a new patch after this many frames (0: never)
  int max_iterations = 10;
  double min_zncc = 0.7;  ///< aligned patches correlating less are not taken
  /// translation: the patch is only moved; similarity: also scaled and rotated, so that a
  /// patch seen nearer or turned since it was taken is not pulled towards its strongest edges;
  /// affine: also sheared and squeezed, as a slanted surface (the floor) is seen from ahead.
  std::string warp = "affine";
  /// A track whose patch no longer aligns (kMismatch) ends, instead of taking a new patch: a
  /// corner on an occluding edge (the background sliding behind it) is no 3D point, and its
  /// patch changes while a surface point's only warps. An unconfirmed patch is taken again.
  bool end_mismatched = true;
  /// Also before the estimator has initialised. Its structure from motion needs points shared
  /// across the whole window, and in low texture every track ended there counts (corridor
  /// restarts after a fault); once tracking, the solve needs the check more.
  bool end_mismatched_before_init = true;
  /// KLT's backward check only for tracks whose patch did not align: an arrival that
  /// aligned to the track's first patch (ZNCC >= min_zncc, within max_shift_px) is taken as
  /// checked. Needs forward_backward_check; not with the corners' gyroscope flow.
  bool skip_backward_when_aligned = false;
};

class PatchAnchors {
 public:
  explicit PatchAnchors(const PatchAnchorOptions& options);

  /// Takes the patch around `p` in the 8-bit `image` as track `id`'s anchor (replacing an
  /// older one). Returns false, and anchors nothing, where the patch leaves the image.
  bool anchor(int id, const cv::Mat& image, const cv::Point2f& p);
  /// Aligns track `id`'s anchored patch to `image`, starting at `*p`; moves `*p` only when
  /// the result is kAligned.
  Alignment refine(int id, const cv::Mat& image, cv::Point2f* p);
  /// One more frame for every track; returns whether `id` is due for a new anchor.
  bool dueForReanchor(int id) const;
  void tick();
  /// Forgets every track not in `ids`.
  void keepOnly(const std::vector<int>& ids);
  void clear() { patches_.clear(); }
  std::size_t size() const { return patches_.size(); }

 private:
  struct Patch {
    /// Zero-mean template, window x window, row-major (kept for the shift alone).
    std::vector<float> values;
    /// Steepest-descent images: the template's gradient times the warp's Jacobian, for the
    /// x- and y-shift, then the linear part's parameters (similarity: scale, rotation;
    /// affine: its four entries) about the patch centre (kept for the shift alone).
    std::array<std::vector<float>, 6> sd;
    /// For the warps: per pixel 8 floats {1, value, sd[0..5]} (unused ones 0), so that one
    /// pass multiplies a warped sample into all its sums at once, each sum still added up in
    /// pixel order.
    std::vector<float> packed;
    float norm = 0;                                   ///< sqrt(sum of values^2)
    Eigen::Matrix<double, 6, 1> sum_sd, sum_sd_t;     ///< sums of sd, and of sd times the values
    Eigen::Matrix2d inv_h2;                           ///< inverse Gauss-Newton matrix, shift alone
    Eigen::Matrix<double, 6, 6> inv_h;                ///< of the whole warp (top-left block)
    Eigen::Matrix2d A = Eigen::Matrix2d::Identity();  ///< the warp's last linear part
    int age = 0;                                      ///< frames since the patch was taken
    bool confirmed = false;                           ///< it has aligned since it was taken
  };
  /// The warp's parameter count (2, 4 or 6), from options_.warp once, not per alignment.
  static int warpParameters(const std::string& warp);
  Alignment refineShift(Patch& t, const cv::Mat& image, cv::Point2f* p) const;
  Alignment refineWarp(Patch& t, const cv::Mat& image, cv::Point2f* p) const;

  PatchAnchorOptions options_;
  int k_params_;
  std::unordered_map<int, Patch> patches_;
  // anchor()'s working buffers, kept so that each new patch does not allocate them again.
  std::vector<float> scratch_big_, scratch_values_;
  std::array<std::vector<float>, 6> scratch_sd_;
};

}  // namespace alvio
