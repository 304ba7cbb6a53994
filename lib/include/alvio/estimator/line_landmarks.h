#pragma once
// Line landmarks of the sliding window: segment observations per window frame
// (keyed by the frame's time in ns, so dropping any frame is one erase), their
// triangulation from the window poses, and the observed extent for maps.
// Lines live in the world frame (not anchored to a keyframe), so removing a
// frame never re-parameterises them.

#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "alvio/frontend/feature_frame.h"
#include "alvio/geometry/line_landmark.h"
#include "alvio/geometry/line_triangulation.h"

namespace alvio {

/// Which retired lines are handed to the maps: a track whose observations do not fit one line
/// (it slid onto a neighbouring edge) or that the cameras barely moved across is placed by
/// noise. The defaults let every line through.
struct LineRetirementFilter {
  /// Largest RMS endpoint-to-line distance over the track (normalised image units).
  double max_reprojection_rms = std::numeric_limits<double>::infinity();
  /// The same for a track fitted on its full-resolution edge positions (lines.map_edges),
  /// which are about twice as precise as the tracker's.
  double max_edge_reprojection_rms = std::numeric_limits<double>::infinity();
  /// Smallest cross parallax (lineCrossParallax: baseline across the line over distance).
  double min_cross_parallax = 0;
  /// Largest 1-sigma position uncertainty of the segment's midpoint across the line [m]
  /// (lineUncertainty at the estimator's line noise).
  double max_midpoint_std_m = std::numeric_limits<double>::infinity();
};

/// What became of the lines that left the window with enough observations and an extent.
struct LineRetirementCounts {
  int retired = 0;              ///< refined over their track and handed to the maps
  int held_back_fit = 0;        ///< track fits worse than max_reprojection_rms (or the edge one)
  int held_back_parallax = 0;   ///< fit fine, but under min_cross_parallax
  int held_back_edge = 0;       ///< looked for on their full-resolution edge, found on under half
  int held_back_uncertain = 0;  ///< passed the rest, midpoint less certain than max_midpoint_std_m
  int tracks() const {
    return retired + held_back_fit + held_back_parallax + held_back_edge + held_back_uncertain;
  }
};

/// The map limits as configured, in the units a user sets them, for run summaries.
struct LineMapLimits {
  double max_rms_px = 0;
  double max_edge_rms_px = 0;  ///< <= 0 when there are no edge positions (lines.map_edges off)
  double min_parallax = 0;
  double max_midpoint_std_m = 0;  ///< <= 0: no limit
};

/// "43 of 148 retired tracks; held back: 73 fit worse than 0.35 px RMS on their edges (0.5 px
/// on the tracker's positions), 32 with cross parallax under 0.1, ..." (the limits as
/// configured), for run summaries and logs.
std::string describeLineRetirement(const LineRetirementCounts& counts, const LineMapLimits& limits);
/// Over three quarters of at least kMinTracksToJudgeTheFitLimit tracks fail the fit limit. On
/// the whole of sim_MH_05, 393 of 1206 (33 %) do (fourteenth session); a camera whose line
/// endpoints are much noisier fails nearly all and needs a looser limit.
inline constexpr int kMinTracksToJudgeTheFitLimit = 200;
bool fitLimitLooksTooTight(const LineRetirementCounts& counts);
/// What to tell the user when fitLimitLooksTooTight.
inline constexpr const char* kFitLimitHint =
    "most line tracks fit worse than estimator.line_map_max_edge_rms_px (or line_map_max_rms_px); "
    "if this camera's line endpoints are noisier, raise them";

class LineLandmarks {
 public:
  /// `min_observations`: window observations a line needs before it is triangulated and used.
  LineLandmarks(int min_observations, const LineTriangulationOptions& triangulation)
      : min_observations_(min_observations), triangulation_(triangulation) {}

  void addFrame(
      int64_t frame_ns,
      const std::vector<LineObservation, Eigen::aligned_allocator<LineObservation>>& lines);
  /// A frame leaves the window: its observations move to the lines' history with the frame's
  /// final camera pose T_w_c. A line left with no window observation retires: it is refined
  /// over its whole history (all its observations, poses fixed) and, if it passes the
  /// retirement filter, queued for takeRetired().
  /// `T_w_c` null: the frame has no estimated pose (before initialisation), so its
  /// observations are dropped instead of kept for the retirement refinement.
  void removeFrame(int64_t frame_ns, const Eigen::Isometry3d* T_w_c);

  /// Triangulate every untriangulated line with enough observations. `camera_pose(ns)`
  /// gives T_w_c of a window frame.
  void triangulate(const std::function<Eigen::Isometry3d(int64_t)>& camera_pose);
  /// Recompute the extents of usable lines from their observations.
  void updateExtents(const std::function<Eigen::Isometry3d(int64_t)>& camera_pose);

  /// Enough window observations to be triangulated and used.
  bool observedEnough(const LineLandmark& l) const {
    return static_cast<int>(l.observations.size()) >= min_observations_;
  }
  /// In the optimisation: triangulated, not an outlier, enough observations.
  bool usable(const LineLandmark& l) const {
    return l.hasLine() && l.status != LineLandmarkStatus::kOutlier && observedEnough(l);
  }
  int usableCount() const;
  void removeIds(const std::vector<int>& ids);
  /// Lines of the last frame that continued an existing track.
  int lastTrackedCount() const { return last_tracked_; }
  void clear() {
    landmarks_.clear();
    history_.clear();
  }
  /// Lines retired since the last call, refined over their whole track (world frame).
  std::vector<LineLandmark> takeRetired();
  /// Endpoint noise [normalised] at which retired lines' uncertainties are computed.
  void setUncertaintySigma(double sigma_normalised) { sigma_ = sigma_normalised; }
  void setRetirementFilter(const LineRetirementFilter& filter) { filter_ = filter; }
  /// Take observations at their full-resolution edge positions (EstimatorOptions::
  /// line_residuals_on_edges).
  void setResidualsOnEdges(bool on) { residuals_on_edges_ = on; }
  /// Since construction (resets included).
  const LineRetirementCounts& retirementCounts() const { return counts_; }

  std::map<int, LineLandmark>& landmarks() { return landmarks_; }
  const std::map<int, LineLandmark>& landmarks() const { return landmarks_; }

 private:
  /// A track's observations from frames that left the window, with their poses.
  struct TrackHistory {
    LineViews views;       ///< the tracker's positions
    LineViews edge_views;  ///< the same on their full-resolution edge, where found
    int edge_checks = 0;   ///< how many of those frames looked for the edge
  };
  void retire(const LineLandmark& l, const TrackHistory& history);
  bool usableForRetirement(const LineLandmark& l, const LineViews& views) const;

  int min_observations_;
  LineTriangulationOptions triangulation_;
  int last_tracked_ = 0;
  std::map<int, LineLandmark> landmarks_;  // by id: deterministic order
  std::map<int, TrackHistory> history_;    // by id
  std::vector<LineLandmark> retired_;
  double sigma_ = 1.5 / 458.0;
  bool residuals_on_edges_ = false;
  LineRetirementFilter filter_;
  LineRetirementCounts counts_;
};

}  // namespace alvio
