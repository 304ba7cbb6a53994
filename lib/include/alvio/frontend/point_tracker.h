#pragma once
// KLT point front end (as in VINS-Mono): Shi-Tomasi corners tracked by
// pyramidal Lucas-Kanade, forward-backward checked, outliers removed by RANSAC
// on the fundamental matrix, new corners detected away from existing ones.

#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <vector>

#include "alvio/camera/camera_model.h"
#include "alvio/common/timing.h"
#include "alvio/frontend/clahe.h"
#include "alvio/frontend/corner_detector.h"
#include "alvio/frontend/feature_frame.h"
#include "alvio/frontend/patch_anchors.h"
#include "alvio/frontend/point_tracker_options.h"
#include "alvio/frontend/pyramid_history.h"

namespace alvio {

class PointTracker {
 public:
  PointTracker(const PointTrackerOptions& options, std::shared_ptr<const CameraModel> camera);

  /// Track into the next 8-bit grey image. Stage times go to `timing` when given.
  /// `mean_intensity`: the scene's mean brightness when the caller has measured it (before
  /// exposure compensation); negative: measured here, on `gray`. `R_cur_prev`: the camera's
  /// rotation since the previous image (GyroRotation), where KLT starts when gyro_flow is on.
  FeatureFrame track(const cv::Mat& gray, int64_t t_ns, FrameTiming* timing = nullptr,
                     double mean_intensity = -1,
                     const std::optional<Eigen::Matrix3d>& R_cur_prev = std::nullopt);
  /// Forget all tracks (after a reset, or an image-size change).
  void reset();
  /// Whether the estimator is tracking (initialised), for anchors.end_mismatched_before_init.
  void setEstimatorTracking(bool tracking) { estimator_tracking_ = tracking; }
  /// How many corners the last frame tracked back for the forward-backward check.
  std::size_t lastBackwardChecks() const { return backward_checks_; }

 private:
  void rejectWithFundamental(std::vector<cv::Point2f>* prev, std::vector<cv::Point2f>* cur,
                             std::vector<int>* ids, std::vector<int>* counts) const;
  void detectNew(const cv::Mat& img);
  /// KLT from `from` in `from_pyramid` to `to` in `to_pyramid` (started at `to` when it is
  /// not empty) on `levels` levels.
  void flow(const std::vector<cv::Mat>& from_pyramid, const std::vector<cv::Mat>& to_pyramid,
            const std::vector<cv::Point2f>& from, std::vector<cv::Point2f>* to,
            std::vector<uchar>* status, int levels) const;
  /// The forward-backward check: KLT back from each arrival in this frame, started at `back`;
  /// true where it comes within forward_backward_max_px of its origin.
  std::vector<uchar> returns(const std::vector<cv::Mat>& prev_pyramid,
                             const std::vector<cv::Mat>& pyramid,
                             const std::vector<cv::Point2f>& arrivals,
                             const std::vector<cv::Point2f>& origins, std::vector<cv::Point2f> back,
                             int levels);
  /// KLT from `from` in the previous pyramid to `to` in this one (started at `to` when it is
  /// not empty) on `levels` levels, then back: a corner that does not return fails. With the
  /// camera's rotation the way back starts where that rotation puts each arrival.
  void flowForwardBackward(const std::vector<cv::Mat>& prev_pyramid,
                           const std::vector<cv::Mat>& pyramid,
                           const std::vector<cv::Point2f>& from, std::vector<cv::Point2f>* to,
                           std::vector<uchar>* status, int levels,
                           const Eigen::Matrix3d* R_cur_prev = nullptr);
  /// Where the rotation R alone moves each (distorted) pixel.
  std::vector<cv::Point2f> rotated(const Eigen::Matrix3d& R,
                                   const std::vector<cv::Point2f>& px) const;
  void alignToAnchors(const cv::Mat& img);
  /// Whether an alignment ends its track: a confirmed patch that stopped fitting, when
  /// anchors.end_mismatched (before initialisation also end_mismatched_before_init).
  bool endsTrack(Alignment a) const;
  /// Takes track `id`'s patch again at `p` when its alignment `a` calls for it.
  void retakePatch(int id, const cv::Mat& img, const cv::Point2f& p, Alignment a);
  /// The tracks `status` keeps move on to `next`, less those the fundamental matrix rejects.
  void advance(std::vector<cv::Point2f> next, const std::vector<uchar>& status);
  /// KLT forward, each arrival aligned to its anchored patch, and only the arrivals no patch
  /// vouches for tracked back (anchors.skip_backward_when_aligned). Updates the tracks.
  void trackAlignedFirst(const std::vector<cv::Mat>& pyramid, const cv::Mat& img);

  PointTrackerOptions options_;
  std::shared_ptr<const CameraModel> camera_;
  bool estimator_tracking_ = false;
  Clahe clahe_;
  CornerDetector corners_;
  PatchAnchors anchors_;
  PyramidHistory pyramids_;  // with gradients, for KLT
  cv::Mat detection_mask_;   // kept between frames: a new one would be paged in every frame
  int64_t prev_t_ns_ = 0;
  std::vector<cv::Point2f> pts_;
  std::vector<int> ids_, track_counts_;
  std::vector<Eigen::Vector2d> prev_xy_;  // by index into pts_ of the previous frame
  std::vector<int> prev_ids_;
  int next_id_ = 0;
  std::size_t backward_checks_ = 0;
};

}  // namespace alvio
