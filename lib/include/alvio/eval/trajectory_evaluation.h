#pragma once
// Trajectory accuracy: timestamp association, alignment, absolute trajectory
// error (ATE) and relative pose error (RPE) over sub-trajectories of fixed
// length, as the TUM benchmark and rpg_trajectory_evaluation define them.

#include <cstddef>
#include <utility>
#include <vector>

#include "alvio/common/types.h"
#include "alvio/eval/alignment.h"

namespace alvio {

/// Pairs (est index, gt index) whose stamps differ by less than `max_dt`, chosen greedily
/// from the closest pair up, each pose used at most once (the TUM benchmark's rule).
/// Returned in est-time order.
std::vector<std::pair<std::size_t, std::size_t>> associateByTime(const Trajectory& est,
                                                                 const Trajectory& gt,
                                                                 double max_dt);

struct ErrorStats {
  std::size_t count = 0;
  double rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0;
  static ErrorStats of(std::vector<double> values);
};

struct RpeSegment {
  double fraction = 0;             ///< of the ground-truth path length
  double length_m = 0;             ///< sub-trajectory length
  ErrorStats translation_percent;  ///< |t error| / length * 100
  ErrorStats rotation_deg_per_m;   ///< rotation error angle / length
};

struct EvaluationOptions {
  AlignmentMode alignment = AlignmentMode::kSE3;
  double max_dt = 0.02;
  std::vector<double> rpe_fractions = {0.1, 0.2, 0.3, 0.4, 0.5};
};

struct EvaluationResult {
  std::size_t est_poses = 0, gt_poses = 0, matched = 0;
  double path_length_m = 0;  ///< ground truth, over the matched span
  Similarity3 alignment;
  ErrorStats ate_translation_m;
  ErrorStats ate_rotation_deg;
  std::vector<RpeSegment> rpe;
  // Per matched pair, for plots: time, aligned estimate, ground truth, error.
  std::vector<double> t;
  Points3 est_aligned, gt_matched;
  std::vector<double> translation_error_m;
};

/// Throws alvio::Error when too few poses match to align.
EvaluationResult evaluateTrajectory(const Trajectory& est, const Trajectory& gt,
                                    const EvaluationOptions& options);

}  // namespace alvio
