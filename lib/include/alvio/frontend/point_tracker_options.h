#pragma once
// Settings of the KLT point front end (config `points:`).

#include <string>

#include "alvio/frontend/patch_anchors.h"

namespace alvio {

class YamlReader;

struct PointTrackerOptions {
  int max_features = 150;    ///< target number of tracked corners
  int min_distance_px = 30;  ///< minimum distance between corners
  /// Look for new corners only when at least this many of max_features are missing (1: every
  /// frame, as VINS-Mono does). Long tracks lose a few points a frame, and the search costs
  /// the same for one corner as for a hundred.
  int min_new_features = 20;
  double quality_level = 0.01;       ///< Shi-Tomasi quality relative to the best corner
  double ransac_threshold_px = 1.0;  ///< fundamental-matrix RANSAC threshold
  bool equalize = true;              ///< CLAHE before tracking (robust to exposure changes)
  double clahe_clip_limit = 3.0;     ///< CLAHE's contrast limit
  int clahe_tiles = 8;               ///< CLAHE's tiles per image side
  /// A frame whose mean brightness jumps by more than this fraction is scaled back to the
  /// previous level before point and line tracking (0: off). See exposure_compensation.h.
  double exposure_jump = 0.15;
  int klt_window = 21;
  int klt_levels = 3;
  /// Start KLT where the gyroscope's rotation since the last frame moves each corner (when the
  /// caller passes that rotation), with gyro_klt_levels pyramid levels above the image; corners
  /// that fail there try again on all klt_levels. On all three levels: on one level the corners
  /// err more in dim light (docs/benchmarks.md, thirty-first and fifty-eighth sessions).
  bool gyro_flow = true;
  int gyro_klt_levels = 3;
  bool forward_backward_check = true;  ///< track back and reject points that do not return
  double forward_backward_max_px = 0.5;
  PatchAnchorOptions anchors;  ///< `points.anchors`: align each track to its anchored patch

  static PointTrackerOptions load(const YamlReader& yaml, const std::string& prefix);
};

}  // namespace alvio
