#pragma once
// Sub-pixel refinement of a detected segment on the full-resolution image. LSD runs at half
// scale for speed, which doubles its error across the line (0.70 px median endpoint distance
// to the true edge on sim_MH_01, 0.35 px at full scale). Here the edge is found again along
// the segment's normal at full resolution: at evenly spaced samples, the peak of the
// intensity derivative across the line (the segment's own polarity, sub-pixel by a parabola),
// and one line fitted through those peaks. The extent stays the detector's.

#include <opencv2/core.hpp>

#include "alvio/lines/line_segment.h"

namespace alvio {

struct EdgeRefinementOptions {
  double search_px = 2.0;          ///< the edge is searched this far either side of the segment
  double sample_spacing_px = 6.0;  ///< distance between samples along the segment
  int max_samples = 24;
  double min_contrast = 4.0;     ///< smallest derivative peak kept [grey levels per px]
  double max_residual_px = 0.6;  ///< peaks further from the fitted line are outliers
  double min_inlier_fraction = 0.6;
  double max_shift_px = 1.5;  ///< the refined line moves the endpoints at most this far
};

/// The segment moved onto the edge that the full-resolution 8-bit grey `image` shows, or
/// false (and `segment` untouched) where the edge is too faint, too short or not one line.
bool refineSegmentToEdge(const cv::Mat& image, const EdgeRefinementOptions& options,
                         LineSegment* segment);

}  // namespace alvio
