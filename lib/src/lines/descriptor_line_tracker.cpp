#include "alvio/lines/descriptor_line_tracker.h"

#include <algorithm>
#include <opencv2/features2d.hpp>

#include "alvio/common/angles.h"

namespace alvio {

DescriptorLineTracker::DescriptorLineTracker(const CameraOptions& camera,
                                             const LineTrackerOptions& options)
    : LineTracker(camera, options) {}

void DescriptorLineTracker::associate(const cv::Mat& undistorted,
                                      const std::vector<LineSegment>& detections, bool /*detected*/,
                                      LineFrame* frame) {
  const auto& o = options_.descriptor;
  const cv::Mat descriptors = lbd_.compute(undistorted, detections);

  // Previous -> current KNN matches that pass the distance, ratio and geometry checks.
  std::vector<cv::DMatch> good;
  if (!prev_descriptors_.empty() && !descriptors.empty()) {
    std::vector<std::vector<cv::DMatch>> knn;
    cv::BFMatcher(cv::NORM_HAMMING).knnMatch(prev_descriptors_, descriptors, knn, 2);
    for (const auto& m : knn) {
      if (m.empty() || m[0].distance >= o.max_hamming_distance) continue;
      if (m.size() > 1 && m[0].distance > o.max_ratio * m[1].distance) continue;
      const LineSegment& prev = prev_segments_[m[0].queryIdx];
      const LineSegment& cur = detections[m[0].trainIdx];
      if (angleDifference(prev.angle(), cur.angle()) > o.max_angle_deg * kDegToRad) continue;
      if ((prev.midpoint() - cur.midpoint()).norm() > o.max_center_distance_px) continue;
      good.push_back(m[0]);
    }
  }
  // One previous ID per current line: the closest descriptor wins.
  std::sort(good.begin(), good.end(),
            [](const cv::DMatch& a, const cv::DMatch& b) { return a.distance < b.distance; });
  std::vector<int> prev_of(detections.size(), -1);
  for (const cv::DMatch& m : good)
    if (prev_of[m.trainIdx] < 0) prev_of[m.trainIdx] = m.queryIdx;

  // Matched lines keep their ID; then new lines, as many as max_lines leaves room for.
  std::vector<int> kept;  // detection indices, in output order
  std::vector<int> ids, counts;
  std::vector<bool> used(detections.size(), false);
  for (std::size_t j = 0; j < detections.size(); ++j) {
    if (prev_of[j] < 0) continue;
    used[j] = true;
    kept.push_back(static_cast<int>(j));
    ids.push_back(prev_ids_[prev_of[j]]);
    counts.push_back(prev_counts_[prev_of[j]] + 1);
    ++frame->stats.tracked;
  }
  for (int j : selectNewLines(detections, used, static_cast<int>(kept.size()))) {
    kept.push_back(j);
    ids.push_back(newId());
    counts.push_back(1);
    ++frame->stats.new_lines;
  }

  frame->lines.clear();
  prev_segments_.clear();
  prev_descriptors_ = cv::Mat();
  for (std::size_t i = 0; i < kept.size(); ++i) {
    const LineSegment& seg = detections[kept[i]];
    LineObservation obs;
    obs.id = ids[i];
    obs.start_px = seg.start;
    obs.end_px = seg.end;
    obs.track_count = counts[i];
    frame->lines.push_back(obs);
    prev_segments_.push_back(seg);
    prev_descriptors_.push_back(descriptors.row(kept[i]));
  }
  prev_ids_ = std::move(ids);
  prev_counts_ = std::move(counts);
}

}  // namespace alvio
