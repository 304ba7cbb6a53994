#pragma once
// ALVIO's optical-flow line tracker (Jung et al., section 2.2).
//
// Per frame:
//  1. Predict: every previous line is sampled at samples_per_line points (both endpoints and
//     interior points) that pyramidal KLT moves into the current frame. A line is fitted to the
//     moved points (consensus over point pairs, then least squares on the agreeing ones); the
//     extent along it comes from the moved endpoints (interior points of a plain edge do not
//     see motion along the edge), and from the one left if the other was lost, keeping the
//     length. A prediction leaving the image is clipped to the border along its own slope
//     (type 4).
//  2. Match: for each prediction the K nearest detections (by perpendicular distance and angle)
//     that are parallel, close to its line and overlap it are candidates; each detection goes to
//     its best prediction.
//  3. Merge and filter: two or more detections of one prediction are merged into one segment
//     (type 3). The result must pass the length-ratio and centre-distance filters, else the best
//     single detection is tried. Matched lines keep their ID (types 1, 3, 4); the remaining
//     detections get new IDs (type 2).
// With flow.detect_every = N > 1 the detector runs on every N-th frame only; on the frames in
// between, step 1's predictions are the lines (no matching, no new lines). A frame whose
// predictions lost over a fifth of the lines makes the next one detect.

#include <opencv2/core.hpp>
#include <vector>

#include "alvio/frontend/pyramid_history.h"
#include "alvio/lines/line_tracker.h"

namespace alvio {

class OpticalFlowLineTracker final : public LineTracker {
 public:
  OpticalFlowLineTracker(const CameraOptions& camera, const LineTrackerOptions& options);
  const char* name() const override { return "flow"; }

  /// A previous line predicted into the current frame.
  struct Prediction {
    LineSegment segment;
    bool valid = false;    ///< enough points were tracked and something is left in the image
    bool clipped = false;  ///< an endpoint was predicted outside the image (type 4)
  };
  /// The predictions made in the last call (one per previous line), for inspection and tests.
  const std::vector<Prediction>& lastPredictions() const { return predictions_; }

 protected:
  bool detectsThisFrame() override;
  void associate(const cv::Mat& undistorted, const std::vector<LineSegment>& detections,
                 bool detected, LineFrame* frame) override;

 private:
  struct Track {
    int id;
    LineSegment segment;
    int count;
  };
  void predict(const std::vector<cv::Mat>& pyramid, cv::Size image_size);
  /// predict() when the flow starts from the gyroscope's rotation: few levels first, then all
  /// levels for the lines that lost a sample or their prediction there.
  void predictFromRotation(const std::vector<cv::Mat>& pyramid, cv::Size image_size,
                           const std::vector<cv::Point2f>& samples);
  cv::Size kltWindow() const;
  cv::TermCriteria kltStop() const;
  /// Whether a KLT window centred on `p` lies wholly outside the image.
  bool windowOutside(const cv::Point2f& p, cv::Size image_size) const;
  /// Whether this frame's flow starts from the gyroscope's rotation.
  bool usesRotation() const { return options_.flow.gyro_flow && rotationSincePrevious(); }
  /// Steps 2 and 3: this frame's lines from the predictions and the detections.
  std::vector<Track> match(const std::vector<LineSegment>& detections, LineFrame* frame);
  /// A frame without detections: the valid predictions are this frame's lines.
  std::vector<Track> carryPredictions(LineFrame* frame) const;
  bool predictOne(const Track& track, const std::vector<cv::Point2f>& moved,
                  const std::vector<uchar>& status, std::size_t first, cv::Size image_size,
                  Prediction* prediction) const;

  std::vector<Track> tracks_;
  PyramidHistory pyramids_;  // with gradients, for KLT
  std::vector<Prediction> predictions_;
  int frames_since_detection_ = 0;
};

}  // namespace alvio
