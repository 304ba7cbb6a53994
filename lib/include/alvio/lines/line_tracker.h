#pragma once
// The line front end's interface: one grey image in, the frame's line observations with
// persistent track IDs out. Implementations: OpticalFlowLineTracker (ALVIO) and
// DescriptorLineTracker (PL-VIO-style baseline).
//
// Every tracker undistorts the raw image to the camera's pinhole image (ImageUndistorter),
// detects LSD segments there (LineDetector) and associates them with the previous frame's
// lines. Tracked lines may continue with segments shorter than a new line must be
// (hysteresis), and take precedence over new lines under the max_lines cap. Pixel coordinates in
// the output are in that pinhole image; normalised ones are K^-1 of them, i.e. undistorted
// normalised coordinates, as the estimator needs.

#include <Eigen/Core>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "alvio/config/sensor_options.h"
#include "alvio/frontend/feature_frame.h"
#include "alvio/lines/image_undistorter.h"
#include "alvio/lines/line_detector.h"
#include "alvio/lines/line_segment.h"
#include "alvio/lines/line_tracker_options.h"

namespace alvio {

struct LineFrame {
  double t = 0.0;
  std::vector<LineObservation, Eigen::aligned_allocator<LineObservation>> lines;
  LineTrackStats stats;
};

class LineTracker {
 public:
  LineTracker(const CameraOptions& camera, const LineTrackerOptions& options);
  virtual ~LineTracker() = default;
  LineTracker(const LineTracker&) = delete;
  LineTracker& operator=(const LineTracker&) = delete;

  /// Process one raw (distorted) 8-bit grey image taken at time t [s]. `R_cur_prev`: the
  /// camera's rotation since the previous image (GyroRotation), for trackers that use it.
  LineFrame track(const cv::Mat& gray, double t,
                  const std::optional<Eigen::Matrix3d>& R_cur_prev = std::nullopt);
  /// Same, for an image already undistorted with undistorter() (to share the remap).
  LineFrame trackUndistorted(const cv::Mat& undistorted, double t,
                             const std::optional<Eigen::Matrix3d>& R_cur_prev = std::nullopt);

  const ImageUndistorter& undistorter() const { return undistorter_; }
  const LineTrackerOptions& options() const { return options_; }
  virtual const char* name() const = 0;

 protected:
  /// Whether the detector runs on this frame (called once per frame, before associate()).
  virtual bool detectsThisFrame() { return true; }
  /// Associate this frame's detections with the previous frame's lines: fill `frame.lines`
  /// (pixel coordinates, id, track_count) and the association counters of `frame.stats`.
  /// `detected` is false when detectsThisFrame() skipped the detector (`detections` is empty).
  virtual void associate(const cv::Mat& undistorted, const std::vector<LineSegment>& detections,
                         bool detected, LineFrame* frame) = 0;
  const LineDetector& detector() const { return detector_; }
  /// The rotation passed with the frame being associated.
  const std::optional<Eigen::Matrix3d>& rotationSincePrevious() const { return R_cur_prev_; }
  int newId() { return next_id_++; }
  /// The unused detections that start new lines this frame: long enough for a new line,
  /// longest first, no more than leave room under max_lines after `tracked` lines.
  std::vector<int> selectNewLines(const std::vector<LineSegment>& detections,
                                  const std::vector<bool>& used, int tracked) const;

  LineTrackerOptions options_;

 private:
  ImageUndistorter undistorter_;
  LineDetector detector_;
  std::optional<Eigen::Matrix3d> R_cur_prev_;
  int next_id_ = 0;
};

/// The tracker named by options.tracker ("flow" or "descriptor").
std::unique_ptr<LineTracker> createLineTracker(const CameraOptions& camera,
                                               const LineTrackerOptions& options);

}  // namespace alvio
