#include "alvio/frontend/point_tracker.h"

#include <algorithm>
#include <numeric>
#include <opencv2/calib3d.hpp>
#include <unordered_map>

#include "alvio/common/error.h"
#include "alvio/frontend/pyramidal_klt.h"
#include "alvio/frontend/rotated_pixels.h"

namespace alvio {

PointTracker::PointTracker(const PointTrackerOptions& options,
                           std::shared_ptr<const CameraModel> camera)
    : options_(options),
      camera_(std::move(camera)),
      clahe_(options.clahe_clip_limit, options.clahe_tiles),
      anchors_(options.anchors) {}

void PointTracker::reset() {
  pyramids_.forgetPrevious();
  pts_.clear();
  ids_.clear();
  track_counts_.clear();
  prev_xy_.clear();
  prev_ids_.clear();
  anchors_.clear();
}

namespace {
template <typename T>
void keep(std::vector<T>* v, const std::vector<uchar>& status) {
  std::size_t j = 0;
  for (std::size_t i = 0; i < v->size(); ++i)
    if (status[i]) (*v)[j++] = (*v)[i];
  v->resize(j);
}
}  // namespace

void PointTracker::rejectWithFundamental(std::vector<cv::Point2f>* prev,
                                         std::vector<cv::Point2f>* cur, std::vector<int>* ids,
                                         std::vector<int>* counts) const {
  if (cur->size() < 8) return;
  // RANSAC in a virtual undistorted pinhole image so the threshold is in pixels.
  const double f = camera_->fx(), cx = camera_->cx(), cy = camera_->cy();
  std::vector<cv::Point2f> un_prev(prev->size()), un_cur(cur->size());
  for (std::size_t i = 0; i < cur->size(); ++i) {
    const Eigen::Vector2d a = camera_->undistort({(*prev)[i].x, (*prev)[i].y});
    const Eigen::Vector2d b = camera_->undistort({(*cur)[i].x, (*cur)[i].y});
    un_prev[i] = cv::Point2f(f * a.x() + cx, f * a.y() + cy);
    un_cur[i] = cv::Point2f(f * b.x() + cx, f * b.y() + cy);
  }
  std::vector<uchar> status;
  cv::findFundamentalMat(un_prev, un_cur, cv::FM_RANSAC, options_.ransac_threshold_px, 0.99,
                         status);
  if (status.size() != cur->size()) return;  // degenerate: keep all
  keep(prev, status);
  keep(cur, status);
  keep(ids, status);
  keep(counts, status);
}

void PointTracker::flow(const std::vector<cv::Mat>& from_pyramid,
                        const std::vector<cv::Mat>& to_pyramid,
                        const std::vector<cv::Point2f>& from, std::vector<cv::Point2f>* to,
                        std::vector<uchar>* status, int levels) const {
  const cv::Size win(options_.klt_window, options_.klt_window);
  const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  trackPyramidalKlt(from_pyramid, to_pyramid, from, to, status, win, levels, stop, !to->empty());
}

std::vector<uchar> PointTracker::returns(const std::vector<cv::Mat>& prev_pyramid,
                                         const std::vector<cv::Mat>& pyramid,
                                         const std::vector<cv::Point2f>& arrivals,
                                         const std::vector<cv::Point2f>& origins,
                                         std::vector<cv::Point2f> back, int levels) {
  backward_checks_ += arrivals.size();
  std::vector<uchar> status;
  flow(pyramid, prev_pyramid, arrivals, &back, &status, levels);
  for (std::size_t i = 0; i < status.size(); ++i)
    status[i] = status[i] && cv::norm(back[i] - origins[i]) <= options_.forward_backward_max_px;
  return status;
}

void PointTracker::flowForwardBackward(const std::vector<cv::Mat>& prev_pyramid,
                                       const std::vector<cv::Mat>& pyramid,
                                       const std::vector<cv::Point2f>& from,
                                       std::vector<cv::Point2f>* to, std::vector<uchar>* status,
                                       int levels, const Eigen::Matrix3d* R_cur_prev) {
  flow(prev_pyramid, pyramid, from, to, status, levels);
  if (!options_.forward_backward_check) return;
  // Back from where the rotation puts each arrival rather than from the start itself, so that
  // a wrong arrival's way back is not handed the right answer. Measured, it let about as many
  // wrong arrivals through (dim light, one level: 4.65 % of corners over 3 px against 4.58 %).
  const std::vector<uchar> back =
      returns(prev_pyramid, pyramid, *to, from,
              R_cur_prev ? rotated(R_cur_prev->transpose(), *to) : from, levels);
  for (std::size_t i = 0; i < status->size(); ++i) (*status)[i] = (*status)[i] && back[i];
}

std::vector<cv::Point2f> PointTracker::rotated(const Eigen::Matrix3d& R,
                                               const std::vector<cv::Point2f>& px) const {
  return rotatedPixels(
      R, px, [&](const Eigen::Vector2d& p) -> Eigen::Vector3d { return camera_->backProject(p); },
      [&](const Eigen::Vector3d& ray, Eigen::Vector2d* out) { return camera_->project(ray, out); });
}

FeatureFrame PointTracker::track(const cv::Mat& gray, int64_t t_ns, FrameTiming* timing,
                                 double mean_intensity,
                                 const std::optional<Eigen::Matrix3d>& R_cur_prev) {
  if (gray.type() != CV_8UC1)
    throw Error("point tracker: expected an 8-bit single-channel image, got type " +
                std::to_string(gray.type()));
  if (gray.cols != camera_->width() || gray.rows != camera_->height())
    throw Error("point tracker: image is " + std::to_string(gray.cols) + "x" +
                std::to_string(gray.rows) + " but the camera is " +
                std::to_string(camera_->width()) + "x" + std::to_string(camera_->height()));
  FeatureFrame frame;
  frame.t_ns = t_ns;
  backward_checks_ = 0;
  frame.mean_intensity = mean_intensity >= 0 ? mean_intensity : cv::mean(gray)[0];

  cv::Mat img;
  {
    ScopedStage stage(timing, "preprocess");
    if (options_.equalize)
      clahe_.apply(gray, img);
    else
      img = gray;
  }

  {
    ScopedStage stage(timing, "point_tracking");
    const cv::Size win(options_.klt_window, options_.klt_window);
    // The image's pyramid and gradients, built once: the forward pass needs the previous
    // frame's, the backward pass this frame's, and this frame's serve the next frame again
    // (calcOpticalFlowPyrLK on plain images would build them four times a frame).
    const std::vector<cv::Mat>& pyramid = pyramids_.build(img, win, options_.klt_levels);
    const std::vector<cv::Mat>& prev_pyramid = pyramids_.previous();
    if (!prev_pyramid.empty() && !pts_.empty()) {
      std::vector<cv::Point2f> next;
      std::vector<uchar> status;
      // Started where the gyroscope's rotation puts them, corners need fewer levels. Those
      // that fail there (a near surface's fast flow) try again on all levels.
      const bool predicted = options_.gyro_flow && R_cur_prev.has_value();
      const bool aligned_first = !predicted && options_.anchors.enabled &&
                                 options_.anchors.skip_backward_when_aligned &&
                                 options_.forward_backward_check;
      if (aligned_first) {
        trackAlignedFirst(pyramid, img);
      } else if (predicted) {
        const std::vector<cv::Point2f> predictions = rotated(*R_cur_prev, pts_);
        next = predictions;
        flowForwardBackward(prev_pyramid, pyramid, pts_, &next, &status, options_.gyro_klt_levels,
                            &*R_cur_prev);
        std::vector<std::size_t> failed;
        std::vector<cv::Point2f> from, to;
        for (std::size_t i = 0; i < status.size(); ++i)
          if (!status[i]) {
            failed.push_back(i);
            from.push_back(pts_[i]);
            to.push_back(predictions[i]);
          }
        if (!failed.empty() && options_.gyro_klt_levels < options_.klt_levels) {
          std::vector<uchar> again;
          flowForwardBackward(prev_pyramid, pyramid, from, &to, &again, options_.klt_levels,
                              &*R_cur_prev);
          for (std::size_t k = 0; k < failed.size(); ++k) {
            next[failed[k]] = to[k];
            status[failed[k]] = again[k];
          }
        }
      } else {
        flowForwardBackward(prev_pyramid, pyramid, pts_, &next, &status, options_.klt_levels);
      }
      if (!aligned_first) {
        for (std::size_t i = 0; i < status.size(); ++i)
          status[i] = status[i] && camera_->inImage({next[i].x, next[i].y}, 1.0);
        advance(std::move(next), status);
        if (options_.anchors.enabled) alignToAnchors(img);
      }
    } else {
      pts_.clear();
      ids_.clear();
      track_counts_.clear();
    }
    pyramids_.advance();
    for (int& c : track_counts_) ++c;
  }

  {
    ScopedStage stage(timing, "point_detection");
    detectNew(img);
    if (options_.anchors.enabled) {
      anchors_.keepOnly(ids_);
      for (std::size_t i = 0; i < pts_.size(); ++i)
        if (track_counts_[i] == 1) anchors_.anchor(ids_[i], img, pts_[i]);
    }
  }

  // Normalised coordinates and their velocities against the previous frame.
  std::unordered_map<int, Eigen::Vector2d> prev_xy;
  for (std::size_t i = 0; i < prev_ids_.size(); ++i) prev_xy[prev_ids_[i]] = prev_xy_[i];
  const double dt = prev_t_ns_ ? (t_ns - prev_t_ns_) * 1e-9 : 0.0;
  prev_xy_.clear();
  prev_ids_.clear();
  frame.points.reserve(pts_.size());
  for (std::size_t i = 0; i < pts_.size(); ++i) {
    PointObservation o;
    o.id = ids_[i];
    o.px = Eigen::Vector2d(pts_[i].x, pts_[i].y);
    o.xy = camera_->undistort(o.px);
    o.track_count = track_counts_[i];
    const auto it = prev_xy.find(o.id);
    if (it != prev_xy.end() && dt > 0) o.velocity = (o.xy - it->second) / dt;
    frame.points.push_back(o);
    prev_xy_.push_back(o.xy);
    prev_ids_.push_back(o.id);
  }
  prev_t_ns_ = t_ns;
  return frame;
}

void PointTracker::alignToAnchors(const cv::Mat& img) {
  anchors_.tick();
  std::vector<uchar> keep_track(pts_.size(), 1);
  for (std::size_t i = 0; i < pts_.size(); ++i) {
    const Alignment a = anchors_.refine(ids_[i], img, &pts_[i]);
    if (endsTrack(a)) {
      keep_track[i] = 0;
      continue;
    }
    retakePatch(ids_[i], img, pts_[i], a);
  }
  keep(&pts_, keep_track);
  keep(&ids_, keep_track);
  keep(&track_counts_, keep_track);
}

bool PointTracker::endsTrack(Alignment a) const {
  return a == Alignment::kMismatch && options_.anchors.end_mismatched &&
         (estimator_tracking_ || options_.anchors.end_mismatched_before_init);
}

void PointTracker::retakePatch(int id, const cv::Mat& img, const cv::Point2f& p, Alignment a) {
  if (a == Alignment::kOutside) return;  // KLT's position; the patch may fit again later
  // A patch that no longer aligns (the view changed too much), that never did (too little
  // texture to anchor: the track goes on KLT alone), or that has served long enough, is
  // taken again where the track is now.
  if (a != Alignment::kAligned || anchors_.dueForReanchor(id)) anchors_.anchor(id, img, p);
}

void PointTracker::trackAlignedFirst(const std::vector<cv::Mat>& pyramid, const cv::Mat& img) {
  std::vector<cv::Point2f> next;
  std::vector<uchar> status;
  flow(pyramids_.previous(), pyramid, pts_, &next, &status, options_.klt_levels);
  anchors_.tick();
  std::vector<Alignment> alignment(pts_.size(), Alignment::kOutside);
  std::vector<std::size_t> unchecked;
  std::vector<cv::Point2f> arrivals, origins;
  for (std::size_t i = 0; i < pts_.size(); ++i) {
    if (!status[i] || !camera_->inImage({next[i].x, next[i].y}, 1.0)) {
      status[i] = 0;
      continue;
    }
    const cv::Point2f arrival = next[i];
    alignment[i] = anchors_.refine(ids_[i], img, &next[i]);
    if (alignment[i] == Alignment::kAligned) continue;
    if (endsTrack(alignment[i])) {
      status[i] = 0;
      continue;
    }
    unchecked.push_back(i);
    arrivals.push_back(arrival);
    origins.push_back(pts_[i]);
  }
  if (!unchecked.empty()) {
    const std::vector<uchar> back =
        returns(pyramids_.previous(), pyramid, arrivals, origins, origins, options_.klt_levels);
    for (std::size_t k = 0; k < unchecked.size(); ++k)
      if (!back[k]) status[unchecked[k]] = 0;
  }
  // The surviving tracks' patches, as in alignToAnchors.
  for (std::size_t i = 0; i < pts_.size(); ++i)
    if (status[i]) retakePatch(ids_[i], img, next[i], alignment[i]);
  advance(std::move(next), status);
}

void PointTracker::advance(std::vector<cv::Point2f> next, const std::vector<uchar>& status) {
  std::vector<cv::Point2f> prev = pts_;
  keep(&prev, status);
  keep(&next, status);
  keep(&ids_, status);
  keep(&track_counts_, status);
  rejectWithFundamental(&prev, &next, &ids_, &track_counts_);
  pts_ = std::move(next);
}

void PointTracker::detectNew(const cv::Mat& img) {
  // Keep the longest-tracked points first, each masking its neighbourhood.
  std::vector<std::size_t> order(pts_.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return track_counts_[a] > track_counts_[b];
  });
  detection_mask_.create(img.size(), CV_8UC1);
  detection_mask_.setTo(255);
  cv::Mat& mask = detection_mask_;
  std::vector<cv::Point2f> pts;
  std::vector<int> ids, counts;
  for (std::size_t i : order) {
    const cv::Point2f& p = pts_[i];
    if (mask.at<uchar>(cvRound(p.y), cvRound(p.x)) == 0) continue;
    pts.push_back(p);
    ids.push_back(ids_[i]);
    counts.push_back(track_counts_[i]);
    cv::circle(mask, p, options_.min_distance_px, 0, -1);
  }
  const int wanted = options_.max_features - static_cast<int>(pts.size());
  if (wanted >= options_.min_new_features) {
    const std::vector<cv::Point2f> corners =
        corners_.detect(img, wanted, options_.quality_level, options_.min_distance_px, mask);
    for (const auto& c : corners) {
      pts.push_back(c);
      ids.push_back(next_id_++);
      counts.push_back(1);
    }
  }
  pts_ = std::move(pts);
  ids_ = std::move(ids);
  track_counts_ = std::move(counts);
}

}  // namespace alvio
