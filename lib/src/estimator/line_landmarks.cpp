#include "alvio/estimator/line_landmarks.h"

#include <cmath>
#include <sstream>

#include "alvio/geometry/line_quality.h"

namespace alvio {

std::string describeLineRetirement(const LineRetirementCounts& counts,
                                   const LineMapLimits& limits) {
  std::ostringstream os;
  os << counts.retired << " of " << counts.tracks()
     << " retired tracks; held back: " << counts.held_back_fit << " fit worse than ";
  if (limits.max_edge_rms_px > 0)
    os << limits.max_edge_rms_px << " px RMS on their edges (" << limits.max_rms_px
       << " px on the tracker's positions), ";
  else
    os << limits.max_rms_px << " px RMS, ";
  os << counts.held_back_parallax << " with cross parallax under " << limits.min_parallax;
  if (counts.held_back_edge > 0)
    os << ", " << counts.held_back_edge << " not found on their edge at full resolution";
  if (limits.max_midpoint_std_m > 0)
    os << ", " << counts.held_back_uncertain << " placed less certainly than "
       << 100 * limits.max_midpoint_std_m << " cm (1 sigma)";
  return os.str();
}

bool fitLimitLooksTooTight(const LineRetirementCounts& counts) {
  const int total = counts.tracks();
  // Right after initialisation the poses are rough and most tracks fail (sim_MH_05, first
  // 300 frames: 46 of 52), so only a long run's counts say something about the camera.
  return total >= kMinTracksToJudgeTheFitLimit && 4 * counts.held_back_fit > 3 * total;
}

namespace {
// An endpoint's motion along its line is the detector's choice of where the segment ends; only
// the motion across the line, from the previous observation's line, is the line's.
void setAcrossLineVelocities(const LineLandmarkObservation& previous, double dt_s,
                             LineLandmarkObservation* obs) {
  const Eigen::Vector2d direction = previous.end_norm - previous.start_norm;
  if (!(dt_s > 0) || direction.norm() < 1e-9) return;
  const Eigen::Vector2d normal = Eigen::Vector2d(-direction.y(), direction.x()).normalized();
  obs->start_velocity = normal * normal.dot(obs->start_norm - previous.start_norm) / dt_s;
  obs->end_velocity = normal * normal.dot(obs->end_norm - previous.start_norm) / dt_s;
}
}  // namespace

void LineLandmarks::addFrame(
    int64_t frame_ns,
    const std::vector<LineObservation, Eigen::aligned_allocator<LineObservation>>& lines) {
  last_tracked_ = 0;
  for (const auto& o : lines) {
    // A track that missed its edge in one frame goes on; only that observation is left out.
    if (residuals_on_edges_ && o.edge_checked && !o.on_edge) continue;
    LineLandmarkObservation obs;
    const bool take_edge = residuals_on_edges_ && o.on_edge;
    obs.start_norm = take_edge ? o.edge_start_norm : o.start_norm;
    obs.end_norm = take_edge ? o.edge_end_norm : o.end_norm;
    obs.edge_checked = o.edge_checked;
    obs.on_edge = o.on_edge;
    obs.edge_start_norm = o.edge_start_norm;
    obs.edge_end_norm = o.edge_end_norm;
    auto [it, inserted] = landmarks_.try_emplace(o.id);
    if (inserted)
      it->second.id = o.id;
    else
      ++last_tracked_;
    auto& observations = it->second.observations;
    if (!observations.empty() && observations.rbegin()->first < frame_ns) {
      LineLandmarkObservation& previous = observations.rbegin()->second;
      const double dt_s = 1e-9 * static_cast<double>(frame_ns - observations.rbegin()->first);
      setAcrossLineVelocities(previous, dt_s, &obs);
      // The track's first observation takes its second's (see PointLandmarks).
      if (observations.size() == 1 && previous.start_velocity.isZero() &&
          previous.end_velocity.isZero()) {
        previous.start_velocity = obs.start_velocity;
        previous.end_velocity = obs.end_velocity;
      }
    }
    observations[frame_ns] = obs;
  }
}

void LineLandmarks::removeFrame(int64_t frame_ns, const Eigen::Isometry3d* T_w_c) {
  for (auto it = landmarks_.begin(); it != landmarks_.end();) {
    LineLandmark& l = it->second;
    const auto obs = l.observations.find(frame_ns);
    if (obs != l.observations.end() && T_w_c) {
      LineView v;
      v.T_w_c = *T_w_c;
      v.start_norm = obs->second.start_norm;
      v.end_norm = obs->second.end_norm;
      TrackHistory& h = history_[l.id];
      h.views.push_back(v);
      h.edge_checks += obs->second.edge_checked;
      if (obs->second.on_edge) {
        v.start_norm = obs->second.edge_start_norm;
        v.end_norm = obs->second.edge_end_norm;
        h.edge_views.push_back(v);
      }
    }
    if (obs != l.observations.end()) l.observations.erase(obs);
    if (!l.observations.empty()) {
      ++it;
      continue;
    }
    retire(l, history_[l.id]);
    history_.erase(l.id);
    it = landmarks_.erase(it);
  }
}

void LineLandmarks::retire(const LineLandmark& l, const TrackHistory& history) {
  // One refinement over every observation of the track, for the map: over those found on
  // their full-resolution edge (lines.map_edges) when they are at least half of the track.
  // The others are left out, not mixed in: the two positions differ by a few tenths of a
  // pixel, and tracks mixing them fitted worse (docs/benchmarks.md, eighteenth session).
  const bool on_edges = 2 * history.edge_views.size() >= history.views.size();
  const LineViews& views = on_edges ? history.edge_views : history.views;
  if (!usableForRetirement(l, views)) return;
  // Looked for on most frames but found on fewer than half: no single clean edge there, and
  // such tracks were the map's least precise (sim_MH_05: 77.7 % precision without them, 71.3 %
  // with them at the tracker's 0.5 px limit).
  if (!on_edges && 2 * history.edge_checks >= static_cast<int>(history.views.size())) {
    ++counts_.held_back_edge;
    return;
  }
  PluckerLine line = l.line_w;
  Eigen::Vector3d a, b;
  if (!refineLine(views, triangulation_, &line) || !lineExtent(line, views, &a, &b, triangulation_))
    return;
  if (lineReprojectionRms(line, views) >
      (on_edges ? filter_.max_edge_reprojection_rms : filter_.max_reprojection_rms)) {
    ++counts_.held_back_fit;
    return;
  }
  if (lineCrossParallax(a, b, views) < filter_.min_cross_parallax) {
    ++counts_.held_back_parallax;
    return;
  }
  const LineUncertainty uncertainty = lineUncertainty(line, 0.5 * (a + b), views, sigma_);
  if (uncertainty.midpoint_std_m > filter_.max_midpoint_std_m) {
    ++counts_.held_back_uncertain;
    return;
  }
  ++counts_.retired;
  LineLandmark retired = l;
  retired.setLine(line, LineLandmarkStatus::kOptimised);
  retired.start_w = a;
  retired.end_w = b;
  retired.has_extent = true;
  retired.direction_std_deg = uncertainty.direction_std_deg;
  retired.midpoint_std_m = uncertainty.midpoint_std_m;
  retired.track_observations = static_cast<int>(views.size());
  retired_.push_back(retired);
}

bool LineLandmarks::usableForRetirement(const LineLandmark& l, const LineViews& views) const {
  return l.hasLine() && l.status != LineLandmarkStatus::kOutlier &&
         static_cast<int>(views.size()) >= min_observations_;
}

std::vector<LineLandmark> LineLandmarks::takeRetired() {
  std::vector<LineLandmark> out;
  out.swap(retired_);
  return out;
}

namespace {
LineViews viewsOf(const LineLandmark& l,
                  const std::function<Eigen::Isometry3d(int64_t)>& camera_pose) {
  LineViews views;
  for (const auto& [ns, obs] : l.observations) {
    LineView v;
    v.T_w_c = camera_pose(ns);
    v.start_norm = obs.start_norm;
    v.end_norm = obs.end_norm;
    views.push_back(v);
  }
  return views;
}
}  // namespace

void LineLandmarks::triangulate(const std::function<Eigen::Isometry3d(int64_t)>& camera_pose) {
  for (auto& [id, l] : landmarks_) {
    if (l.hasLine() || !observedEnough(l)) continue;
    PluckerLine line;
    if (triangulateLineMultiView(viewsOf(l, camera_pose), triangulation_, &line) !=
        LineTriangulationStatus::kOk)
      continue;  // degenerate for now; more motion may make it observable
    l.setLine(line, LineLandmarkStatus::kTriangulated);
    Eigen::Vector3d a, b;
    if (lineExtent(line, viewsOf(l, camera_pose), &a, &b, triangulation_)) {
      l.start_w = a;
      l.end_w = b;
      l.has_extent = true;
    }
  }
}

void LineLandmarks::updateExtents(const std::function<Eigen::Isometry3d(int64_t)>& camera_pose) {
  for (auto& [id, l] : landmarks_) {
    if (!usable(l)) continue;
    Eigen::Vector3d a, b;
    if (lineExtent(l.line_w, viewsOf(l, camera_pose), &a, &b, triangulation_)) l.unionExtent(a, b);
  }
}

int LineLandmarks::usableCount() const {
  int n = 0;
  for (const auto& [id, l] : landmarks_) n += usable(l);
  return n;
}

void LineLandmarks::removeIds(const std::vector<int>& ids) {
  // The history goes too: the tracker keeps the id, and a landmark re-created under it must
  // not inherit the views that made this one an outlier (nor keep them forever if it is not).
  for (int id : ids) {
    landmarks_.erase(id);
    history_.erase(id);
  }
}

}  // namespace alvio
