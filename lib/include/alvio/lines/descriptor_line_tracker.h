#pragma once
// Baseline line tracker as in PL-VIO: LBD descriptors of the current detections are KNN-matched
// (Hamming, k = 2) to the previous frame's, without any motion prediction. A match needs a
// Hamming distance below max_hamming_distance, optionally a ratio test, and a sane geometry
// (angle and centre displacement); each current line takes at most one previous ID. Split lines
// (type 3) and lines leaving the image (type 4) are not handled: they usually get new IDs.

#include <opencv2/core.hpp>
#include <vector>

#include "alvio/lines/lbd_extractor.h"
#include "alvio/lines/line_tracker.h"

namespace alvio {

class DescriptorLineTracker final : public LineTracker {
 public:
  DescriptorLineTracker(const CameraOptions& camera, const LineTrackerOptions& options);
  const char* name() const override { return "descriptor"; }

 protected:
  /// Detects on every frame (descriptors need detections), so `detected` is always true.
  void associate(const cv::Mat& undistorted, const std::vector<LineSegment>& detections,
                 bool detected, LineFrame* frame) override;

 private:
  LbdExtractor lbd_;
  std::vector<LineSegment> prev_segments_;
  std::vector<int> prev_ids_, prev_counts_;
  cv::Mat prev_descriptors_;
};

}  // namespace alvio
