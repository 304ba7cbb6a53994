#pragma once
// Options of the line front end, read from the `lines:` section of the configuration:
//
//   lines:
//     tracker: flow            # flow (ALVIO, optical flow) | descriptor (PL-VIO, LBD KNN)
//     detector: {min_length_ratio: 0.06, max_lines: 60, lsd_scale: 0.5, ...}
//     flow: {...}
//     descriptor: {...}
//
// Every key is optional; the defaults are tuned for 752x480 EuRoC images at 20 Hz.

#include <string>

namespace alvio {

class YamlReader;

struct LineDetectorOptions {
  /// "lsd" (LSD as in the paper, with linear-time seed ordering: linear_time_lsd.h),
  /// "opencv_lsd" (OpenCV's cv::LineSegmentDetector, needed for lsd_refine) or "fld" (ximgproc's
  /// FastLineDetector: Canny edges fitted by lines).
  std::string method = "lsd";
  /// Minimum length of a new line as a fraction of the image diagonal (0.06 * 892 px = 54 px).
  double min_length_ratio = 0.06;
  /// A tracked line may continue with (and a split line be merged from) segments down to this
  /// fraction of the minimum length: hysteresis, so that a line near the threshold does not
  /// flicker in and out.
  double continuation_length_factor = 0.5;
  /// At most this many lines per frame: the tracked ones first, then new ones, longest first.
  int max_lines = 60;
  /// The detector keeps at most this many segments (the longest), to bound the association.
  int max_detections = 150;
  /// LSD works on the image scaled by this factor (OpenCV's `scale`); 0.5 halves the
  /// detection time on EuRoC at a small loss of short segments.
  double lsd_scale = 0.5;
  /// LSD's Gaussian sigma factor (sigma = lsd_sigma_scale / lsd_scale).
  double lsd_sigma_scale = 0.6;
  /// At lsd_scale 0.5 (method lsd), halve the image with an image pyramid's 5-tap Gaussian
  /// (cv::pyrDown) instead of the lsd_sigma_scale blur and a resize: about 0.4 ms less per
  /// detection on EuRoC-sized images.
  bool lsd_pyramid_downscale = false;
  /// FLD works on the image resized by this factor (area averaging). 0.5 is 3.5x faster than
  /// LSD at its 0.5, but its flow tracks are a third shorter (docs/benchmarks.md).
  double fld_scale = 1.0;
  /// LSD_REFINE_STD (true: splits segments at bends; method opencv_lsd only) or LSD_REFINE_NONE.
  bool lsd_refine = false;
  /// LSD's bound on the gradient's quantisation error (OpenCV's `quant`): pixels whose
  /// gradient is under quant / sin(22.5 deg) grow no region. Larger skips faint edges.
  double lsd_quant = 2.0;
  /// Mean grey level [0, 255] at which lsd_quant holds (0: always). A darker frame's threshold
  /// is scaled by its mean / this, down to lsd_min_quant_scale: LSD then keeps the edges it
  /// would find in the frame brightened to this level, which dim light would otherwise lose.
  /// Frames at least this bright are unchanged. Both LSDs; FLD has no such threshold.
  double lsd_reference_brightness = 0.0;
  double lsd_min_quant_scale = 0.25;
  /// Segments must keep this distance [px] from the invalid (unmapped) border of the
  /// undistorted image.
  int border_margin_px = 2;
  /// Move each segment found on a scaled image onto its edge in the full-resolution image
  /// (edge_refinement.h).
  bool refine_edges = false;

  static LineDetectorOptions load(const YamlReader& yaml, const std::string& prefix);
  void validate(const std::string& where) const;
};

struct FlowLineTrackerOptions {
  /// Points tracked per line with KLT: both endpoints and (n - 2) evenly spaced interior ones.
  int samples_per_line = 5;
  int klt_window_px = 15;
  int klt_pyramid_levels = 3;
  /// Start the samples' KLT where the gyroscope's rotation since the last frame moves them
  /// (when the caller passes that rotation), with gyro_klt_levels pyramid levels instead of
  /// klt_pyramid_levels.
  bool gyro_flow = true;
  int gyro_klt_levels = 1;
  int klt_max_iterations = 30;
  double klt_epsilon = 0.01;
  /// Candidate detections kept per predicted line (the K of the KNN matching).
  int knn = 4;
  /// A detection matches a predicted line if its direction differs by at most this angle
  /// [deg] and both its endpoints lie within max_line_distance_px of the predicted line.
  double max_angle_deg = 8.0;
  double max_line_distance_px = 5.0;
  /// ... and if it overlaps the predicted segment by at least this fraction of the shorter.
  double min_overlap_ratio = 0.5;
  /// The matched (possibly merged) segment must have a length within [r, 1/r] of the
  /// predicted one and a centre within max_center_distance_px of it.
  double min_length_ratio = 0.5;
  double max_center_distance_px = 50.0;
  /// The detector runs on every N-th frame only; in between, tracked lines continue on their
  /// optical-flow predictions (which already fit a line to KLT samples) and no line starts.
  /// 1: every frame, as in the paper. 2 halves LSD's cost, and tracks last 1.5x longer with
  /// as many correct associations (docs/benchmarks.md).
  int detect_every = 2;

  static FlowLineTrackerOptions load(const YamlReader& yaml, const std::string& prefix);
  void validate(const std::string& where) const;
};

struct DescriptorLineTrackerOptions {
  /// LBD matches need a Hamming distance below this (of 256 bits), as in PL-VIO.
  int max_hamming_distance = 30;
  /// Lowe ratio between the best and second-best Hamming distance (1 disables it).
  double max_ratio = 1.0;
  /// Geometric sanity checks of a match (the previous and current segment).
  double max_angle_deg = 10.0;
  double max_center_distance_px = 60.0;

  static DescriptorLineTrackerOptions load(const YamlReader& yaml, const std::string& prefix);
  void validate(const std::string& where) const;
};

struct LineTrackerOptions {
  std::string tracker = "flow";  ///< "flow" or "descriptor"
  /// Track lines in a thread of their own, beside the point tracker (FrontEnd). The frames are
  /// the same either way; offline on two cores sim_MH_05 took 89 s instead of 103 s.
  bool own_thread = false;
  /// Each observation is also moved onto its edge at full resolution (edge_refinement.h), for
  /// the line map's final fit; the tracks and the estimator are unchanged.
  bool map_edges = true;
  LineDetectorOptions detector;
  FlowLineTrackerOptions flow;
  DescriptorLineTrackerOptions descriptor;

  /// Read `prefix` ("lines"); absent keys keep their defaults, bad values throw alvio::Error
  /// naming the file and key.
  static LineTrackerOptions load(const YamlReader& yaml, const std::string& prefix);
  void validate(const std::string& where) const;
};

}  // namespace alvio
