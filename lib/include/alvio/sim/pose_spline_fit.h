#pragma once
// Fitting a smoothing PoseSpline to sampled poses (a ground-truth file). The
// EuRoC ground truth has steps of several cm within one 5 ms sample (laser
// tracker re-locks), so the fit is a regularised least-squares problem, not an
// interpolation: data terms with a Huber loss plus penalties on the second
// differences of the control points (acceleration, angular acceleration).

#include <string>

#include "alvio/common/types.h"
#include "alvio/sim/pose_spline.h"

namespace alvio::sim {

struct SplineFitOptions {
  double knot_spacing_s = 0.05;
  /// Expected noise of a sample; residuals are divided by it.
  double position_sigma_m = 0.002;
  double rotation_sigma_rad = 0.002;
  /// Size of the second-difference penalty, expressed as the acceleration
  /// (m/s^2) and angular acceleration (rad/s^2) that cost as much as one sigma.
  double acceleration_sigma = 1.0;
  double angular_acceleration_sigma = 30.0;
  /// Huber thresholds in units of sigma (robust to isolated glitches).
  double huber_threshold = 3.0;
  int max_iterations = 30;
};

/// How far the spline is from the samples it was fitted to.
struct SplineFitReport {
  int samples = 0;
  double position_rms_m = 0.0;
  double position_max_m = 0.0;
  double rotation_rms_deg = 0.0;
  double rotation_max_deg = 0.0;
  double max_error_time = 0.0;  ///< time of the largest position error
  std::string summary() const;
};

/// Fit `samples` (time-ordered, >= 2 poses). Deterministic (single-threaded solve).
PoseSpline fitPoseSpline(const Trajectory& samples, const SplineFitOptions& options = {},
                         SplineFitReport* report = nullptr);

/// Residuals of `spline` against `samples` (those inside its time domain).
SplineFitReport evaluateSplineFit(const PoseSpline& spline, const Trajectory& samples);

}  // namespace alvio::sim
