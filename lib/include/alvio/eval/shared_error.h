#pragma once
// How much of two runs' trajectory error is the same error. Two configurations fed the same
// images share their point tracks, and with them the tracks' errors: their ATEs can then
// differ little although one of them adds information. Each run is aligned to the ground
// truth on its own, as its ATE is; at the times both runs have a pose, each error vector
// e = aligned estimate - truth is split into the part both share, c = (e_a + e_b) / 2, and
// the part that differs, d = (e_a - e_b) / 2.

#include <Eigen/Core>
#include <cstddef>

#include "alvio/eval/trajectory_evaluation.h"

namespace alvio {

struct SharedError {
  std::size_t matched = 0;      ///< poses both runs have
  double rms_a = 0, rms_b = 0;  ///< each run's ATE over those poses, m
  double rms_shared = 0;        ///< RMS of |c|, m
  double rms_difference = 0;    ///< RMS of |e_a - e_b|, m
  /// mean |c|² / (mean |c|² + mean |d|²): 1 when both runs err alike, 0 for opposite errors,
  /// about 0.5 for unrelated ones of equal size.
  double shared_fraction = 0;
  /// Correlation of e_a and e_b along the world's x, y and z.
  Eigen::Vector3d axis_correlation = Eigen::Vector3d::Zero();
};

/// Pairs the two evaluations' poses by time (within max_dt). Throws alvio::Error when fewer
/// than three poses pair up.
SharedError sharedError(const EvaluationResult& a, const EvaluationResult& b, double max_dt);

}  // namespace alvio
