#include "alvio/lines/optical_flow_line_tracker.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "alvio/common/angles.h"
#include "alvio/frontend/pyramidal_klt.h"
#include "alvio/frontend/rotated_pixels.h"

namespace alvio {
namespace {
// A moved sample further than this from the consensus line is an outlier [px].
constexpr double kFlowOutlierPx = 2.0;
// The along-line scale between frames is trusted only within this range (else a shift).
constexpr double kMinAlongScale = 0.67, kMaxAlongScale = 1.5;
// The flow of a frame that predicted fewer of its lines than this is not trusted to carry
// lines without detection on the next frame.
constexpr double kMinReliableFlowFraction = 0.8;

// The line through the largest set of points within kFlowOutlierPx of the line through some
// pair of them (all pairs are tried: a handful of samples per line), refitted to that set. A
// KLT point on a plain edge can slide far off when its surroundings change (an occluder), so a
// plain least-squares fit is not enough.
bool consensusLineFit(const std::vector<Eigen::Vector2d>& points, const Eigen::Vector2d& reference,
                      LineSegment* fit, std::vector<bool>* inlier) {
  const std::size_t n = points.size();
  std::size_t best_count = 0;
  double best_spread = 0.0;
  std::vector<bool> best(n, false), current(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const LineSegment pair(points[i], points[j]);
      if (pair.length() < 2.0 * kFlowOutlierPx) continue;
      std::size_t count = 0;
      for (std::size_t k = 0; k < n; ++k)
        count += current[k] = pair.distanceToLine(points[k]) <= kFlowOutlierPx;
      // Ties go to the pair spanning more of the line.
      if (count > best_count || (count == best_count && pair.length() > best_spread)) {
        best_count = count;
        best_spread = pair.length();
        best = current;
      }
    }
  }
  // Half of the tracked samples at least must agree, and two at the very least.
  if (best_count < 2 || 2 * best_count < n) return false;
  std::vector<Eigen::Vector2d> inliers;
  for (std::size_t k = 0; k < n; ++k)
    if (best[k]) inliers.push_back(points[k]);
  *inlier = best;
  return fitSegmentToPoints(inliers, reference, fit);
}

struct Candidate {
  int prediction;
  int detection;
  double cost;
};
}  // namespace

OpticalFlowLineTracker::OpticalFlowLineTracker(const CameraOptions& camera,
                                               const LineTrackerOptions& options)
    : LineTracker(camera, options) {}

bool OpticalFlowLineTracker::predictOne(const Track& track, const std::vector<cv::Point2f>& moved,
                                        const std::vector<uchar>& status, std::size_t first,
                                        cv::Size image_size, Prediction* prediction) const {
  const int n = options_.flow.samples_per_line;
  const double length = track.segment.length();
  std::vector<double> along_prev;
  std::vector<int> sample;  // index k of each kept point: 0 and n - 1 are the endpoints
  std::vector<Eigen::Vector2d> points;
  along_prev.reserve(n);
  sample.reserve(n);
  points.reserve(n);
  // Samples within half a KLT window of the border are tracked with a truncated window and
  // drift; an endpoint that the border cut off is not a point of the scene either.
  const double margin = 0.5 * options_.flow.klt_window_px;
  const Eigen::Vector2d step = (track.segment.end - track.segment.start) / (n - 1.0);
  for (int k = 0; k < n; ++k) {
    const cv::Point2f& p = moved[first + k];
    if (!status[first + k] || !std::isfinite(p.x) || !std::isfinite(p.y)) continue;
    const Eigen::Vector2d before = track.segment.start + k * step;
    if (before.x() < margin || before.y() < margin || before.x() > image_size.width - 1 - margin ||
        before.y() > image_size.height - 1 - margin)
      continue;
    along_prev.push_back(length * k / (n - 1));
    sample.push_back(k);
    points.emplace_back(p.x, p.y);
  }
  const Eigen::Vector2d reference = track.segment.end - track.segment.start;
  std::vector<bool> inlier;
  LineSegment fit;
  if (!consensusLineFit(points, reference, &fit, &inlier)) return false;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!inlier[i]) continue;
    points[kept] = points[i];
    along_prev[kept] = along_prev[i];
    sample[kept] = sample[i];
    ++kept;
  }
  points.resize(kept);
  along_prev.resize(kept);
  sample.resize(kept);
  // Positions along the new line as a function s = a t + b of the old ones. Interior samples
  // sit on a plain edge, where KLT only sees the motion across the edge (aperture problem), so
  // the extent comes from the endpoints: both -> a and b; one -> a shift (a = 1); none -> the
  // mean shift of the interior samples.
  const std::size_t m = points.size();
  std::vector<double> along_cur(m);
  for (std::size_t i = 0; i < m; ++i) along_cur[i] = fit.positionAlong(points[i]);
  int i_start = -1, i_end = -1;
  for (std::size_t i = 0; i < m; ++i) {
    if (sample[i] == 0) i_start = static_cast<int>(i);
    if (sample[i] == n - 1) i_end = static_cast<int>(i);
  }
  double a = 1.0, b = 0.0;
  if (i_start >= 0 && i_end >= 0) {
    a = (along_cur[i_end] - along_cur[i_start]) / length;
    b = along_cur[i_start];
    if (!(a >= kMinAlongScale && a <= kMaxAlongScale)) {
      a = 1.0;
      b = 0.5 * (along_cur[i_start] + along_cur[i_end] - length);
    }
  } else if (i_start >= 0) {
    b = along_cur[i_start];
  } else if (i_end >= 0) {
    b = along_cur[i_end] - length;
  } else {
    for (std::size_t i = 0; i < m; ++i) b += (along_cur[i] - along_prev[i]) / m;
  }
  prediction->segment = LineSegment(fit.pointAt(b), fit.pointAt(a * length + b));
  prediction->clipped = false;
  return clipSegmentToRect(&prediction->segment, 0.0, 0.0, image_size.width - 1.0,
                           image_size.height - 1.0, &prediction->clipped);
}

void OpticalFlowLineTracker::predict(const std::vector<cv::Mat>& pyramid, cv::Size image_size) {
  predictions_.assign(tracks_.size(), Prediction());
  if (tracks_.empty()) return;
  const int n = options_.flow.samples_per_line;
  std::vector<cv::Point2f> samples;
  samples.reserve(tracks_.size() * n);
  for (const Track& track : tracks_) {
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector2d p =
          track.segment.start + (track.segment.end - track.segment.start) * (double(k) / (n - 1));
      samples.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
    }
  }
  if (usesRotation()) {
    predictFromRotation(pyramid, image_size, samples);
    return;
  }
  std::vector<cv::Point2f> moved;
  std::vector<uchar> status;
  trackPyramidalKlt(pyramids_.previous(), pyramid, samples, &moved, &status, kltWindow(),
                    options_.flow.klt_pyramid_levels, kltStop(), false);
  for (std::size_t i = 0; i < moved.size(); ++i)
    status[i] = status[i] && !windowOutside(moved[i], image_size);
  for (std::size_t i = 0; i < tracks_.size(); ++i)
    predictions_[i].valid =
        predictOne(tracks_[i], moved, status, i * n, image_size, &predictions_[i]);
}

void OpticalFlowLineTracker::predictFromRotation(const std::vector<cv::Mat>& pyramid,
                                                 cv::Size image_size,
                                                 const std::vector<cv::Point2f>& samples) {
  const auto& f = options_.flow;
  const std::size_t n = static_cast<std::size_t>(f.samples_per_line);
  // Started where the gyroscope's rotation puts them (in the pinhole image the homography
  // K R K^-1), samples need fewer levels; those that fail there try again on all levels.
  const std::vector<cv::Point2f> predicted = rotatedPixels(
      *rotationSincePrevious(), samples,
      [&](const Eigen::Vector2d& p) -> Eigen::Vector3d {
        return undistorter().pixelToNormalised(p).homogeneous();
      },
      [&](const Eigen::Vector3d& ray, Eigen::Vector2d* out) {
        if (ray.z() <= 0) return false;
        *out = undistorter().normalisedToPixel(ray.hnormalized());
        return true;
      });
  std::vector<cv::Point2f> moved = predicted;
  std::vector<uchar> status;
  trackPyramidalKlt(pyramids_.previous(), pyramid, samples, &moved, &status, kltWindow(),
                    f.gyro_klt_levels, kltStop(), true);
  for (std::size_t i = 0; i < moved.size(); ++i)
    status[i] = status[i] && !windowOutside(moved[i], image_size);
  // A line the few levels lost, or lost a sample of, tries again on all levels.
  std::vector<std::size_t> again_lines;
  for (std::size_t t = 0; t < tracks_.size(); ++t) {
    predictions_[t].valid =
        predictOne(tracks_[t], moved, status, t * n, image_size, &predictions_[t]);
    const bool all_samples = std::all_of(status.begin() + t * n, status.begin() + (t + 1) * n,
                                         [](uchar ok) { return ok != 0; });
    if (!predictions_[t].valid || !all_samples) again_lines.push_back(t);
  }
  if (again_lines.empty() || f.gyro_klt_levels >= f.klt_pyramid_levels) return;
  std::vector<cv::Point2f> from, to;
  for (std::size_t t : again_lines)
    for (std::size_t k = 0; k < n; ++k) {
      from.push_back(samples[t * n + k]);
      to.push_back(predicted[t * n + k]);
    }
  std::vector<uchar> again;
  trackPyramidalKlt(pyramids_.previous(), pyramid, from, &to, &again, kltWindow(),
                    f.klt_pyramid_levels, kltStop(), true);
  for (std::size_t j = 0; j < again_lines.size(); ++j) {
    const std::size_t t = again_lines[j];
    for (std::size_t k = 0; k < n; ++k) {
      moved[t * n + k] = to[j * n + k];
      status[t * n + k] = again[j * n + k] && !windowOutside(to[j * n + k], image_size);
    }
    predictions_[t] = Prediction();
    predictions_[t].valid =
        predictOne(tracks_[t], moved, status, t * n, image_size, &predictions_[t]);
  }
}

cv::Size OpticalFlowLineTracker::kltWindow() const {
  return cv::Size(options_.flow.klt_window_px, options_.flow.klt_window_px);
}

cv::TermCriteria OpticalFlowLineTracker::kltStop() const {
  return cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                          options_.flow.klt_max_iterations, options_.flow.klt_epsilon);
}

bool OpticalFlowLineTracker::windowOutside(const cv::Point2f& p, cv::Size image_size) const {
  // OpenCV fails a point whose window ended up wholly outside the image only while computing
  // its error; fail it here instead (the same tracks as with the error).
  const int side = options_.flow.klt_window_px;
  const float half = (side - 1) * 0.5f;
  auto off = [&](float x, int size) {
    const int corner = cvFloor(x - half);
    return corner < -side || corner >= size;
  };
  return off(p.x, image_size.width) || off(p.y, image_size.height);
}

bool OpticalFlowLineTracker::detectsThisFrame() {
  // Without lines to carry forward only the detector can start some. When the last frame's
  // flow lost many lines (fast motion, a light change), the survivors are checked against
  // detections too: a carried line is only as good as its flow.
  // predictions_ still holds the last frame's flow.
  const auto kept = std::count_if(predictions_.begin(), predictions_.end(),
                                  [](const Prediction& p) { return p.valid; });
  const bool flow_reliable =
      static_cast<double>(kept) >= kMinReliableFlowFraction * predictions_.size();
  if (tracks_.empty() || !flow_reliable ||
      frames_since_detection_ + 1 >= options_.flow.detect_every) {
    frames_since_detection_ = 0;
    return true;
  }
  ++frames_since_detection_;
  return false;
}

void OpticalFlowLineTracker::associate(const cv::Mat& undistorted,
                                       const std::vector<LineSegment>& detections, bool detected,
                                       LineFrame* frame) {
  const auto& f = options_.flow;
  // Built once per frame and kept as the next frame's previous pyramid.
  const std::vector<cv::Mat>& pyramid =
      pyramids_.build(undistorted, kltWindow(), f.klt_pyramid_levels);
  predict(pyramid, undistorted.size());
  std::vector<Track> next = detected ? match(detections, frame) : carryPredictions(frame);

  frame->lines.clear();
  for (const Track& t : next) {
    LineObservation obs;
    obs.id = t.id;
    obs.start_px = t.segment.start;
    obs.end_px = t.segment.end;
    obs.track_count = t.count;
    frame->lines.push_back(obs);
  }
  tracks_ = std::move(next);
  pyramids_.advance();
}

std::vector<OpticalFlowLineTracker::Track> OpticalFlowLineTracker::carryPredictions(
    LineFrame* frame) const {
  std::vector<Track> next;
  for (std::size_t i = 0; i < predictions_.size(); ++i) {
    const Prediction& p = predictions_[i];
    // As short as a detection may be and still continue a track, at the least.
    if (!p.valid || p.segment.length() < detector().shortestLength()) continue;
    next.push_back({tracks_[i].id, p.segment, tracks_[i].count + 1});
    ++frame->stats.tracked;
    frame->stats.clipped += p.clipped;
  }
  return next;
}

std::vector<OpticalFlowLineTracker::Track> OpticalFlowLineTracker::match(
    const std::vector<LineSegment>& detections, LineFrame* frame) {
  const auto& f = options_.flow;
  // Candidates: the K best detections per prediction that pass angle, distance and overlap.
  const double max_angle = f.max_angle_deg * kDegToRad;
  // Each segment's angle once, not once per pair.
  std::vector<double> detection_angles(detections.size());
  for (std::size_t j = 0; j < detections.size(); ++j) detection_angles[j] = detections[j].angle();
  std::vector<Candidate> candidates;
  for (std::size_t i = 0; i < predictions_.size(); ++i) {
    if (!predictions_[i].valid) continue;
    const LineSegment& pred = predictions_[i].segment;
    const double pred_angle = pred.angle();
    std::vector<Candidate> own;
    for (std::size_t j = 0; j < detections.size(); ++j) {
      const LineSegment& det = detections[j];
      const double dangle = angleDifference(pred_angle, detection_angles[j]);
      if (dangle > max_angle) continue;
      const double d0 = pred.distanceToLine(det.start), d1 = pred.distanceToLine(det.end);
      if (std::max(d0, d1) > f.max_line_distance_px) continue;
      if (projectedOverlap(pred, det) < f.min_overlap_ratio * std::min(pred.length(), det.length()))
        continue;
      // One pixel of offset weighs as much as one degree of angle.
      own.push_back(
          {static_cast<int>(i), static_cast<int>(j), 0.5 * (d0 + d1) + dangle / kDegToRad});
    }
    std::sort(own.begin(), own.end(),
              [](const Candidate& a, const Candidate& b) { return a.cost < b.cost; });
    if (static_cast<int>(own.size()) > f.knn) own.resize(f.knn);
    candidates.insert(candidates.end(), own.begin(), own.end());
  }
  // Each detection goes to its best prediction.
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.cost < b.cost; });
  std::vector<int> owner(detections.size(), -1);
  std::vector<std::vector<int>> assigned(predictions_.size());  // detections, best first
  for (const Candidate& c : candidates) {
    if (owner[c.detection] >= 0) continue;
    owner[c.detection] = c.prediction;
    assigned[c.prediction].push_back(c.detection);
  }

  // Merge (type 3) and filter; a rejected assignment frees its detections.
  auto passesFilters = [&](const LineSegment& pred, const LineSegment& seg) {
    const double ratio = seg.length() / pred.length();
    return ratio >= f.min_length_ratio && ratio <= 1.0 / f.min_length_ratio &&
           (seg.midpoint() - pred.midpoint()).norm() <= f.max_center_distance_px;
  };
  std::vector<bool> used(detections.size(), false);
  std::vector<Track> next;
  for (std::size_t i = 0; i < predictions_.size(); ++i) {
    const std::vector<int>& dets = assigned[i];
    if (dets.empty()) continue;
    const LineSegment& pred = predictions_[i].segment;
    LineSegment result;
    bool merged = false, accepted = false;
    if (dets.size() >= 2) {
      std::vector<LineSegment> pieces;
      for (int j : dets) pieces.push_back(detections[j]);
      result = mergeCollinearSegments(pieces);
      accepted = merged = passesFilters(pred, result);
      if (merged)
        for (int j : dets) used[j] = true;
    }
    if (!accepted && passesFilters(pred, detections[dets.front()])) {
      result = detections[dets.front()];
      used[dets.front()] = accepted = true;
    }
    if (!accepted) continue;
    next.push_back({tracks_[i].id, result, tracks_[i].count + 1});
    ++frame->stats.tracked;
    frame->stats.merged += merged;
    frame->stats.clipped += predictions_[i].clipped;
  }
  for (int j : selectNewLines(detections, used, static_cast<int>(next.size()))) {
    next.push_back({newId(), detections[j], 1});
    ++frame->stats.new_lines;
  }
  return next;
}

}  // namespace alvio
