#pragma once
// Options of the sliding-window estimator (config section "estimator").

#include <string>

#include "alvio/estimator/feature_selection.h"
#include "alvio/estimator/line_landmarks.h"
#include "alvio/geometry/line_triangulation.h"

namespace alvio {

class YamlReader;

struct EstimatorOptions {
  int window_size = 10;                ///< keyframes in the window (plus the newest frame)
  double keyframe_parallax_px = 15;    ///< mean parallax that makes a frame a keyframe [px]
  int max_iterations = 2;              ///< Ceres iterations per frame (no time limit: determinism)
  int init_max_iterations = 24;        ///< ...for the first solve after (re-)initialisation
  int num_threads = 1;                 ///< Ceres threads
  double point_sigma_px = 1.5;         ///< reprojection noise of points
  double point_drift_px2_per_s = 0.0;  ///< tracking drift: variance (px^2) per second of age
  std::string robust_loss = "cauchy";  ///< cauchy | huber | none
  double robust_loss_scale = 1.0;      ///< in units of sigma
  double outlier_reprojection_px = 3.0;  ///< landmarks with a larger mean error are removed
  double imu_noise_scale = 1.0;          ///< multiplies every IMU noise density and random walk
  /// The IMU noise the preintegration is weighted with, when it is not the sensor's
  /// datasheet noise of `imu:` (a real IMU in flight: rotor vibration; see
  /// config/euroc_real.yaml). Keys estimator.imu_noise.*; each <= 0: the sensor's value.
  struct ImuNoiseOverride {
    double accelerometer_noise_density = 0, gyroscope_noise_density = 0;
    double accelerometer_random_walk = 0, gyroscope_random_walk = 0;
  } imu_noise;

  bool record_analysis = false;  ///< keep WindowTrackRecords (alvio run --analysis)
  /// Estimate the camera's time shift on top of camera.timeshift_cam_imu (VINS-Mono's td):
  /// a parameter of the window moving every observation along its image velocity.
  bool estimate_time_shift = false;
  /// How fast the shift may drift [s per sqrt(s)]: its random walk, by which the window's
  /// prior forgets old evidence of it. 0: a constant shift.
  double time_shift_random_walk = 0.0;
  /// The shift is held while the window turns slower than this (RMS, rad/s): on a steady
  /// translation it is nearly unobservable (a shift moves every pose along the path alike).
  double time_shift_min_turn_rate = 0.3;

  // Lines.
  bool use_lines = true;          ///< line landmarks in the optimisation
  double line_sigma_px = 0.35;    ///< endpoint-to-line noise weighing the line residuals [px]
  int line_min_observations = 3;  ///< window observations before a line is used
  double line_outlier_px = 2.0;   ///< lines with a larger mean endpoint error are removed
  /// The residuals and triangulation take each line observation's full-resolution edge
  /// position (lines.map_edges) instead of the tracker's, and leave out observations whose
  /// edge was looked for and not found (the track goes on).
  bool line_residuals_on_edges = false;
  /// Square root of the information [1/rad] pulling each line back to where the solve
  /// started it (LineStepDampingFactor); 0: off.
  double line_step_damping = 10.0;
  LineTriangulationOptions line_triangulation;
  /// A retired line reaches the maps only if its whole track fits it within this RMS
  /// endpoint distance [px] (<= 0: no limit) and the cameras moved across it by at least this
  /// fraction of its distance (lineCrossParallax; 0: no limit). Tuned on the rendered
  /// benchmark (docs/truth_evaluation.md); the trajectory does not depend on them.
  double line_map_max_rms_px = 0.5;
  /// The RMS limit for a track fitted on its full-resolution edge positions (lines.map_edges).
  double line_map_max_edge_rms_px = 0.35;
  double line_map_min_parallax = 0.10;
  /// Endpoint noise [px] behind the lines' uncertainties (midpoint and direction standard
  /// deviations), which the map filters cut on. Kept apart from line_sigma_px, a weight tuned
  /// for the trajectory, so that tuning it leaves the maps alone.
  double line_map_sigma_px = 1.5;
  /// Largest 1-sigma uncertainty of a map line's midpoint across the line [m], from its whole
  /// track at line_map_sigma_px with the poses taken as exact (<= 0: no limit).
  double line_map_max_midpoint_std_m = 0.03;

  /// Sensitivity-based selection and adaptive weighting (estimator.selection).
  FeatureSelectionOptions selection;

  // Initialisation.
  /// Rotation-compensated parallax, reference frame to newest, needed to initialise. A
  /// wide baseline gives a good scale; after `init_relax_after_s` of motion without one
  /// (hand-held wiggles, hovering), `init_relaxed_parallax_px` is enough.
  double init_min_parallax_px = 40;
  double init_relaxed_parallax_px = 40;
  double init_relax_after_s = 1.5;
  int init_min_correspondences = 15;
  double init_retry_interval_s = 0.1;
  double init_min_excitation = 0.005;  ///< std of mean acceleration per frame [m/s^2]
  double init_accel_bias_sigma = 0.2;  ///< bias prior at initialisation [m/s^2] (<= 0: none)
  double init_gyro_bias_sigma = 0.05;  ///< [rad/s]
  double init_max_accel_bias = 0.5;    ///< reject an initialisation that needs a larger bias
  /// Wait until the window's motion departs this far from constant velocity (m; 0: off): the
  /// alignment reads the scale from that departure (AlignmentResult::scale_motion_m).
  double init_min_scale_motion_m = 0.005;
  double init_scale_motion_max_wait_s = 3;  ///< ...for this long at most
  /// After alignment the window keeps being optimised, without output, until one frame moves
  /// its scale by less than this fraction (a short burst of motion leaves the scale loose)...
  double init_settle_change = 0.001;
  double init_settle_max_s = 1.5;  ///< ...or for this long at most. 0: output at once.
  /// After a reset, start the new window from the IMU's dead reckoning of the last output
  /// (gravity, velocity, biases: the scale is known) instead of structure from motion, when
  /// that output is at most this old [s] and every frame of the window sees
  /// `warm_restart_min_points` points triangulated from its poses and lines with enough
  /// observations to be placed. 0: always structure from motion.
  double warm_restart_max_s = 3.0;
  int warm_restart_min_points = 10;
  /// No IMU sample for longer than this [s]: the window is reset instead of bridging the gap
  /// by holding or interpolating samples, and restarts by structure from motion once the IMU
  /// is back (the dead reckoning stops at the gap).
  double max_imu_gap_s = 1.0;

  // Failure detection (reset and re-initialise).
  int min_tracked_features = 3;  ///< fewer points + lines tracked into a frame: reset
  double max_accel_bias = 2.5;   ///< m/s^2
  double max_gyro_bias = 1.0;    ///< rad/s
  double max_translation_jump_m = 5.0;
  double max_z_jump_m = 1.0;
  double max_rotation_jump_deg = 50.0;

  static EstimatorOptions load(const YamlReader& yaml, const std::string& prefix);
};

/// The map limits that apply, for run summaries: the edge fit limit only with edge positions.
LineMapLimits lineMapLimits(const EstimatorOptions& options, bool edge_positions);

}  // namespace alvio
