#include "alvio/estimator/estimator_options.h"

#include <utility>

#include "alvio/common/error.h"
#include "alvio/config/yaml_reader.h"

namespace alvio {

EstimatorOptions EstimatorOptions::load(const YamlReader& yaml, const std::string& prefix) {
  EstimatorOptions o;
  const std::string p = prefix + ".";
  o.window_size = yaml.getInt(p + "window_size", o.window_size);
  o.keyframe_parallax_px = yaml.getDouble(p + "keyframe_parallax_px", o.keyframe_parallax_px);
  o.max_iterations = yaml.getInt(p + "max_iterations", o.max_iterations);
  o.init_max_iterations = yaml.getInt(p + "init_max_iterations", o.init_max_iterations);
  o.num_threads = yaml.getInt(p + "num_threads", o.num_threads);
  o.point_sigma_px = yaml.getDouble(p + "point_sigma_px", o.point_sigma_px);
  o.point_drift_px2_per_s = yaml.getDouble(p + "point_drift_px2_per_s", o.point_drift_px2_per_s);
  o.robust_loss = yaml.getChoice(p + "robust_loss", o.robust_loss, {"cauchy", "huber", "none"});
  o.robust_loss_scale = yaml.getDouble(p + "robust_loss_scale", o.robust_loss_scale);
  o.outlier_reprojection_px =
      yaml.getDouble(p + "outlier_reprojection_px", o.outlier_reprojection_px);
  o.imu_noise_scale = yaml.getDouble(p + "imu_noise_scale", o.imu_noise_scale);
  for (auto [key, value] :
       {std::pair{"accelerometer_noise_density", &o.imu_noise.accelerometer_noise_density},
        {"gyroscope_noise_density", &o.imu_noise.gyroscope_noise_density},
        {"accelerometer_random_walk", &o.imu_noise.accelerometer_random_walk},
        {"gyroscope_random_walk", &o.imu_noise.gyroscope_random_walk}}) {
    const std::string k = p + "imu_noise." + key;
    *value = yaml.getDouble(k, *value);
    if (*value < 0) throw Error(yaml.where(k) + " must not be negative (0: the sensor's value)");
  }
  o.use_lines = yaml.getBool(p + "use_lines", o.use_lines);
  o.record_analysis = yaml.getBool(p + "record_analysis", o.record_analysis);
  o.estimate_time_shift = yaml.getBool(p + "estimate_time_shift", o.estimate_time_shift);
  o.time_shift_random_walk = yaml.getDouble(p + "time_shift_random_walk", o.time_shift_random_walk);
  o.time_shift_min_turn_rate =
      yaml.getDouble(p + "time_shift_min_turn_rate", o.time_shift_min_turn_rate);
  o.line_sigma_px = yaml.getDouble(p + "line_sigma_px", o.line_sigma_px);
  o.line_min_observations = yaml.getInt(p + "line_min_observations", o.line_min_observations);
  o.line_outlier_px = yaml.getDouble(p + "line_outlier_px", o.line_outlier_px);
  o.line_step_damping = yaml.getDouble(p + "line_step_damping", o.line_step_damping);
  o.line_triangulation = LineTriangulationOptions::load(yaml, p + "line_triangulation");
  o.line_map_max_rms_px = yaml.getDouble(p + "line_map_max_rms_px", o.line_map_max_rms_px);
  o.line_map_min_parallax = yaml.getDouble(p + "line_map_min_parallax", o.line_map_min_parallax);
  o.line_map_max_edge_rms_px =
      yaml.getDouble(p + "line_map_max_edge_rms_px", o.line_map_max_edge_rms_px);
  o.line_map_sigma_px = yaml.getDouble(p + "line_map_sigma_px", o.line_map_sigma_px);
  o.line_residuals_on_edges =
      yaml.getBool(p + "line_residuals_on_edges", o.line_residuals_on_edges);
  o.line_map_max_midpoint_std_m =
      yaml.getDouble(p + "line_map_max_midpoint_std_m", o.line_map_max_midpoint_std_m);
  o.selection = FeatureSelectionOptions::load(yaml, p + "selection");
  o.init_min_parallax_px = yaml.getDouble(p + "init_min_parallax_px", o.init_min_parallax_px);
  o.init_relaxed_parallax_px =
      yaml.getDouble(p + "init_relaxed_parallax_px", o.init_relaxed_parallax_px);
  o.init_relax_after_s = yaml.getDouble(p + "init_relax_after_s", o.init_relax_after_s);
  o.init_min_correspondences =
      yaml.getInt(p + "init_min_correspondences", o.init_min_correspondences);
  o.init_retry_interval_s = yaml.getDouble(p + "init_retry_interval_s", o.init_retry_interval_s);
  o.init_max_accel_bias = yaml.getDouble(p + "init_max_accel_bias", o.init_max_accel_bias);
  o.init_min_scale_motion_m =
      yaml.getDouble(p + "init_min_scale_motion_m", o.init_min_scale_motion_m);
  o.init_scale_motion_max_wait_s =
      yaml.getDouble(p + "init_scale_motion_max_wait_s", o.init_scale_motion_max_wait_s);
  o.init_settle_change = yaml.getDouble(p + "init_settle_change", o.init_settle_change);
  o.init_settle_max_s = yaml.getDouble(p + "init_settle_max_s", o.init_settle_max_s);
  o.warm_restart_max_s = yaml.getDouble(p + "warm_restart_max_s", o.warm_restart_max_s);
  o.warm_restart_min_points = yaml.getInt(p + "warm_restart_min_points", o.warm_restart_min_points);
  o.max_imu_gap_s = yaml.getDouble(p + "max_imu_gap_s", o.max_imu_gap_s);
  o.init_min_excitation = yaml.getDouble(p + "init_min_excitation", o.init_min_excitation);
  o.init_accel_bias_sigma = yaml.getDouble(p + "init_accel_bias_sigma", o.init_accel_bias_sigma);
  o.init_gyro_bias_sigma = yaml.getDouble(p + "init_gyro_bias_sigma", o.init_gyro_bias_sigma);
  o.min_tracked_features = yaml.getInt(p + "min_tracked_features", o.min_tracked_features);
  o.max_accel_bias = yaml.getDouble(p + "max_accel_bias", o.max_accel_bias);
  o.max_gyro_bias = yaml.getDouble(p + "max_gyro_bias", o.max_gyro_bias);
  o.max_translation_jump_m = yaml.getDouble(p + "max_translation_jump_m", o.max_translation_jump_m);
  o.max_z_jump_m = yaml.getDouble(p + "max_z_jump_m", o.max_z_jump_m);
  o.max_rotation_jump_deg = yaml.getDouble(p + "max_rotation_jump_deg", o.max_rotation_jump_deg);
  if (o.window_size < 4) throw Error(yaml.where(p + "window_size") + " must be at least 4");
  if (o.max_iterations < 1) throw Error(yaml.where(p + "max_iterations") + " must be at least 1");
  if (o.init_max_iterations < 1)
    throw Error(yaml.where(p + "init_max_iterations") + " must be at least 1");
  if (o.init_min_scale_motion_m < 0)
    throw Error(yaml.where(p + "init_min_scale_motion_m") + " must not be negative (0: off)");
  if (o.init_scale_motion_max_wait_s < 0)
    throw Error(yaml.where(p + "init_scale_motion_max_wait_s") + " must not be negative");
  if (o.init_settle_change < 0)
    throw Error(yaml.where(p + "init_settle_change") + " must not be negative");
  if (o.init_settle_max_s < 0)
    throw Error(yaml.where(p + "init_settle_max_s") + " must not be negative");
  if (o.warm_restart_max_s < 0)
    throw Error(yaml.where(p + "warm_restart_max_s") + " must not be negative (0: off)");
  if (o.warm_restart_min_points < 1)
    throw Error(yaml.where(p + "warm_restart_min_points") + " must be at least 1");
  if (!(o.max_imu_gap_s > 0)) throw Error(yaml.where(p + "max_imu_gap_s") + " must be positive");
  if (o.num_threads < 1) throw Error(yaml.where(p + "num_threads") + " must be at least 1");
  if (o.point_sigma_px <= 0) throw Error(yaml.where(p + "point_sigma_px") + " must be positive");
  if (o.point_drift_px2_per_s < 0)
    throw Error(yaml.where(p + "point_drift_px2_per_s") + " must not be negative (0: no drift)");
  if (o.line_sigma_px <= 0) throw Error(yaml.where(p + "line_sigma_px") + " must be positive");
  if (o.line_map_sigma_px <= 0)
    throw Error(yaml.where(p + "line_map_sigma_px") + " must be positive");
  if (o.line_min_observations < 2)
    throw Error(yaml.where(p + "line_min_observations") + " must be at least 2");
  if (o.line_step_damping < 0)
    throw Error(yaml.where(p + "line_step_damping") + " must not be negative (0: off)");
  if (o.line_map_min_parallax < 0)
    throw Error(yaml.where(p + "line_map_min_parallax") + " must not be negative (0: no limit)");
  if (o.time_shift_random_walk < 0)
    throw Error(yaml.where(p + "time_shift_random_walk") + " must not be negative (0: constant)");
  if (o.imu_noise_scale <= 0) throw Error(yaml.where(p + "imu_noise_scale") + " must be positive");
  return o;
}

LineMapLimits lineMapLimits(const EstimatorOptions& options, bool edge_positions) {
  LineMapLimits limits;
  limits.max_rms_px = options.line_map_max_rms_px;
  limits.max_edge_rms_px = edge_positions ? options.line_map_max_edge_rms_px : 0.0;
  limits.min_parallax = options.line_map_min_parallax;
  limits.max_midpoint_std_m = options.line_map_max_midpoint_std_m;
  return limits;
}

}  // namespace alvio
