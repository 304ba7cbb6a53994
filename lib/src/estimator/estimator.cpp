#include "alvio/estimator/estimator.h"

#include <cmath>
#include <cstdio>
#include <limits>

#include "alvio/common/angles.h"
#include "alvio/common/clock_jump.h"
#include "alvio/common/error.h"
#include "alvio/common/logging.h"
#include "alvio/common/rotation.h"
#include "alvio/estimator/factors/marginalization.h"

namespace alvio {

Estimator::Estimator(const EstimatorOptions& options, const CameraOptions& camera,
                     const ImuOptions& imu)
    : options_(options),
      camera_(camera),
      imu_options_(imu),
      T_b_c_(camera.T_b_c),
      gravity_(0, 0, -imu.gravity_magnitude),
      W_(options.window_size),
      points_(options.window_size, options.keyframe_parallax_px / camera.intrinsics[0]),
      lines_(options.line_min_observations, options.line_triangulation),
      para_pose_(options.window_size + 1),
      para_speed_bias_(options.window_size + 1) {
  lines_.setUncertaintySigma(options.line_map_sigma_px / camera.intrinsics[0]);
  lines_.setResidualsOnEdges(options.line_residuals_on_edges);
  LineRetirementFilter filter;
  if (options.line_map_max_rms_px > 0)
    filter.max_reprojection_rms = options.line_map_max_rms_px / camera.intrinsics[0];
  if (options.line_map_max_edge_rms_px > 0)
    filter.max_edge_reprojection_rms = options.line_map_max_edge_rms_px / camera.intrinsics[0];
  filter.min_cross_parallax = options.line_map_min_parallax;
  if (options.line_map_max_midpoint_std_m > 0)
    filter.max_midpoint_std_m = options.line_map_max_midpoint_std_m;
  lines_.setRetirementFilter(filter);
  clearState();
}

Estimator::~Estimator() = default;

ImuNoise Estimator::imuNoise() const {
  const double s = options_.imu_noise_scale;
  const auto& o = options_.imu_noise;
  const auto pick = [s](double override_value, double sensor) {
    return s * (override_value > 0 ? override_value : sensor);
  };
  ImuNoise n;
  n.acc_noise_density =
      pick(o.accelerometer_noise_density, imu_options_.accelerometer_noise_density);
  n.gyr_noise_density = pick(o.gyroscope_noise_density, imu_options_.gyroscope_noise_density);
  n.acc_random_walk = pick(o.accelerometer_random_walk, imu_options_.accelerometer_random_walk);
  n.gyr_random_walk = pick(o.gyroscope_random_walk, imu_options_.gyroscope_random_walk);
  return n;
}

void Estimator::clearState() {
  const int n = W_ + 1;
  headers_.assign(n, 0.0);
  header_ns_.assign(n, 0);
  intensity_.assign(n, 0.0);
  Ps_.assign(n, Eigen::Vector3d::Zero());
  Vs_.assign(n, Eigen::Vector3d::Zero());
  Bas_.assign(n, Eigen::Vector3d::Zero());
  Bgs_.assign(n, Eigen::Vector3d::Zero());
  Rs_.assign(n, Eigen::Matrix3d::Identity());
  preintegrations_.clear();
  preintegrations_.resize(n);
  dt_buf_.assign(n, {});
  acc_buf_.assign(n, {});
  gyr_buf_.assign(n, {});
  points_.clear();
  lines_.clear();
  last_marginalization_.reset();
  last_marginalization_blocks_.clear();
  all_frames_.clear();
  tmp_preintegration_.reset();
  status_ = EstimatorStatus::kInitializing;
  marginalization_ = Marginalization::kOld;
  frame_count_ = 0;
  last_init_attempt_ = -1e9;
  first_moving_attempt_ = -1;
  first_steady_alignment_ = -1;
  last_wait_reason_.clear();
  bias_prior_pending_ = false;
  warm_seeded_ = false;
  settling_ = false;
  settling_positions_.clear();
}

void Estimator::event(EstimatorEvent::Kind kind, double t, const std::string& message) {
  EstimatorEvent e;
  e.kind = kind;
  e.t = t;
  e.message = message;
  events_.push_back(std::move(e));
}

std::vector<EstimatorEvent> Estimator::takeEvents() {
  std::vector<EstimatorEvent> out;
  out.swap(events_);
  return out;
}

void Estimator::addImu(const ImuSample& s) {
  std::size_t n = 0;
  if (clockJumpedBack(s.t_ns, last_queued_imu_ns_) && s.acc.allFinite() && s.gyr.allFinite()) {
    // The window and the queued IMU belong to the old clock: start again on the new one.
    char why[64];
    std::snprintf(why, sizeof(why), "IMU clock jumped back %.3f s",
                  (last_queued_imu_ns_ - s.t_ns) * 1e-9);
    reset(s.t(), why);
    warm_restart_armed_ = false;  // dead reckoning across the jump means nothing
    imu_queue_.clear();
    has_imu_ = false;
    last_queued_imu_ns_ = 0;
    ++clock_jumps_;
  }
  if (has_imu_ || !imu_queue_.empty()) {
    if (s.t_ns <= last_queued_imu_ns_) {
      if (imu_late_.shouldLog(s.t_ns * 1e-9, &n))
        logWarn(n, " IMU sample(s) not after the previous one dropped (latest at ", s.t_ns,
                " ns, previous ", last_queued_imu_ns_, " ns)");
      return;
    }
  }
  if (!s.acc.allFinite() || !s.gyr.allFinite()) {
    if (imu_nonfinite_.shouldLog(s.t_ns * 1e-9, &n))
      logWarn(n, " IMU sample(s) with a NaN or Inf value dropped (latest at ", s.t_ns, " ns)");
    return;
  }
  last_queued_imu_ns_ = s.t_ns;
  imu_queue_.push_back(s);
}

void Estimator::feedImu(double t, const Eigen::Vector3d& acc, const Eigen::Vector3d& gyr) {
  if (!has_imu_) {
    has_imu_ = true;
    imu_time_ = t;
    acc_0_ = acc;
    gyr_0_ = gyr;
    return;
  }
  const double dt = t - imu_time_;
  if (dt <= 0) return;
  processImu(dt, acc, gyr);
  imu_time_ = t;
}

void Estimator::consumeImuUpTo(double t) {
  while (!imu_queue_.empty() && imu_queue_.front().t() <= t) {
    const ImuSample& s = imu_queue_.front();
    if (has_imu_ && s.t() - last_real_imu_t_ > options_.max_imu_gap_s)
      imuMissing(s.t(), s.t() - last_real_imu_t_);
    last_real_imu_t_ = s.t();
    feedImu(s.t(), s.acc, s.gyr);
    imu_queue_.pop_front();
  }
  if (!has_imu_ || imu_time_ >= t) return;
  // The frame lies in a gap: neither hold the last sample across it nor interpolate over it.
  const double next = imu_queue_.empty() ? t : imu_queue_.front().t();
  if (next - last_real_imu_t_ > options_.max_imu_gap_s) {
    imuMissing(t, next - last_real_imu_t_);
    return;
  }
  // Close the interval exactly at the frame time: interpolate with the next sample, or hold
  // the last one when the next has not arrived.
  Eigen::Vector3d acc = acc_0_, gyr = gyr_0_;
  if (!imu_queue_.empty()) {
    const ImuSample& next = imu_queue_.front();
    const double w = (t - imu_time_) / (next.t() - imu_time_);
    acc = (1 - w) * acc_0_ + w * next.acc;
    gyr = (1 - w) * gyr_0_ + w * next.gyr;
  }
  feedImu(t, acc, gyr);
}

void Estimator::imuMissing(double t, double gap_s) {
  char why[64];
  std::snprintf(why, sizeof(why), "no IMU for %.2f s", gap_s);
  if (frame_count_ > 0 || have_output_) {
    reset(t, why);
    warm_restart_armed_ = false;  // its dead reckoning guessed across the gap
  } else {
    logWarn(why, " at t=", stampText(t));
  }
  has_imu_ = false;
}

void Estimator::processImu(double dt, const Eigen::Vector3d& acc, const Eigen::Vector3d& gyr) {
  const int j = frame_count_;
  if (!preintegrations_[j])
    preintegrations_[j] =
        std::make_unique<ImuPreintegration>(acc_0_, gyr_0_, Bas_[j], Bgs_[j], imuNoise());
  if (j != 0) {
    preintegrations_[j]->push(dt, acc, gyr);
    if (tmp_preintegration_) tmp_preintegration_->push(dt, acc, gyr);
    dt_buf_[j].push_back(dt);
    acc_buf_[j].push_back(acc);
    gyr_buf_[j].push_back(gyr);
    // Propagate the newest state: the prediction for the next optimisation.
    const Eigen::Vector3d a0 = Rs_[j] * (acc_0_ - Bas_[j]) + gravity_;
    const Eigen::Vector3d w = 0.5 * (gyr_0_ + gyr) - Bgs_[j];
    Rs_[j] = Rs_[j] * expQuaternion(w * dt).toRotationMatrix();
    const Eigen::Vector3d a1 = Rs_[j] * (acc - Bas_[j]) + gravity_;
    const Eigen::Vector3d a = 0.5 * (a0 + a1);
    Ps_[j] += dt * Vs_[j] + 0.5 * dt * dt * a;
    Vs_[j] += dt * a;
  }
  if (have_output_) {
    // Dead-reckon the last output state (output frame, midpoint rule): after a reset this
    // carries the pose through the outage.
    BodyState& d = dead_reckoned_;
    const Eigen::Matrix3d R0 = d.q.toRotationMatrix();
    const Eigen::Vector3d a0 = R0 * (acc_0_ - d.ba) + gravity_;
    const Eigen::Matrix3d R1 =
        R0 * expQuaternion((0.5 * (gyr_0_ + gyr) - d.bg) * dt).toRotationMatrix();
    const Eigen::Vector3d a = 0.5 * (a0 + R1 * (acc - d.ba) + gravity_);
    d.p += dt * d.v + 0.5 * dt * dt * a;
    d.v += dt * a;
    d.q = Eigen::Quaterniond(R1).normalized();
    d.t += dt;
  }
  acc_0_ = acc;
  gyr_0_ = gyr;
}

bool Estimator::addFrame(const FeatureFrame& frame, FrameTiming* timing) {
  const double t = frame.t();
  consumeImuUpTo(t);
  if (!has_imu_) {
    event(EstimatorEvent::Kind::kWaiting, t, "no IMU data before this frame");
    return false;
  }
  if (status_ == EstimatorStatus::kInitializing && frame_count_ == 0 && warm_restart_armed_)
    seedFromDeadReckoning(t);
  marginalization_ = points_.addFrameAndCheckParallax(frame_count_, frame)
                         ? Marginalization::kOld
                         : Marginalization::kSecondNew;
  // A window that starts with frames without points (the black frames of a camera fault)
  // cannot initialise: slide them out one a frame, instead of one a keyframe.
  if (status_ == EstimatorStatus::kInitializing && frame_count_ == W_ &&
      marginalization_ == Marginalization::kSecondNew && !points_.seenIn(0))
    marginalization_ = Marginalization::kOld;
  headers_[frame_count_] = t;
  header_ns_[frame_count_] = frame.t_ns;
  intensity_[frame_count_] = frame.mean_intensity;
  if (options_.use_lines) lines_.addFrame(frame.t_ns, frame.lines);

  ImageFrame image;
  for (const auto& o : frame.points) image.xy1[o.id] = Eigen::Vector3d(o.xy.x(), o.xy.y(), 1.0);
  image.imu = std::move(tmp_preintegration_);
  all_frames_[frame.t_ns] = std::move(image);
  tmp_preintegration_ = std::make_unique<ImuPreintegration>(acc_0_, gyr_0_, Bas_[frame_count_],
                                                            Bgs_[frame_count_], imuNoise());

  if (status_ == EstimatorStatus::kInitializing) {
    if (frame_count_ < W_) {
      ++frame_count_;
      // The new slot starts from the previous frame's state.
      Ps_[frame_count_] = Ps_[frame_count_ - 1];
      Vs_[frame_count_] = Vs_[frame_count_ - 1];
      Rs_[frame_count_] = Rs_[frame_count_ - 1];
      Bas_[frame_count_] = Bas_[frame_count_ - 1];
      Bgs_[frame_count_] = Bgs_[frame_count_ - 1];
      return false;
    }
    bool ok = false;
    if (t - last_init_attempt_ >= options_.init_retry_interval_s) {
      last_init_attempt_ = t;
      ScopedStage stage(timing, "initialization");
      ok = initialize(t);
    }
    if (!ok) {
      slideWindow();
      return false;
    }
    status_ = EstimatorStatus::kTracking;
    // Initialisation ends with a first visual-inertial optimisation of the aligned window,
    // given more iterations than the per-frame ones: the linear alignment is only a start.
    // Lines join from the next frame on. A line keeps its first triangulation as each solve's
    // start, and its step damping pulls it back there: lines placed from the alignment's
    // poses would carry the alignment's scale error for as long as they stay.
    optimize(timing, options_.init_max_iterations, /*triangulate_lines=*/false);
    // A window with too little excitation can align to a wrong gravity; the refinement then
    // pushes the error into the accelerometer bias. Reject such an initialisation and wait.
    if (Bas_[W_].norm() > options_.init_max_accel_bias || !Ps_[W_].allFinite()) {
      const std::string why = "initialisation rejected: accelerometer bias " +
                              std::to_string(Bas_[W_].norm()) + " m/s^2 after refinement";
      logInfo(why);
      event(EstimatorEvent::Kind::kWaiting, t, why);
      const Eigen::Vector3d bg = Bgs_[W_];
      clearState();
      for (auto& b : Bgs_) b = bg.allFinite() ? bg : Eigen::Vector3d::Zero();
      return false;
    }
    settling_ = options_.init_settle_max_s > 0;
    settle_start_ = t;
    if (!settling_)
      initialized(t);
    else
      rememberSettlingWindow();
  } else {
    const int tracked = points_.lastTrackedCount() + lines_.lastTrackedCount();
    if (tracked < options_.min_tracked_features) {
      reset(t, "only " + std::to_string(points_.lastTrackedCount()) + " points and " +
                   std::to_string(lines_.lastTrackedCount()) + " lines tracked");
      return false;
    }
    optimize(timing, options_.max_iterations);
    std::string why;
    if (detectFailure(&why)) {
      reset(t, why);
      return false;
    }
    if (settling_) {
      // A solve that took no step left the window where it was: no sign that it has settled.
      const bool settled =
          stats_.accepted_steps > 0 && windowScaleChange() <= options_.init_settle_change;
      if (settled || t - settle_start_ >= options_.init_settle_max_s) {
        settling_ = false;
        initialized(t);
      } else {
        rememberSettlingWindow();
      }
    }
  }
  {
    ScopedStage stage(timing, "marginalization");
    marginalize();
  }
  slideWindow();
  points_.removeFailures();
  last_R_ = Rs_[W_];
  last_P_ = Ps_[W_];
  if (settling_) return false;
  // Output continuity: after a reset, anchor the new world frame on the dead-reckoned pose.
  if (align_output_after_reset_) {
    align_output_after_reset_ = false;
    out_yaw_ = yawAlignment(dead_reckoned_.q.toRotationMatrix(), Rs_[W_]);
    out_from_ = Ps_[W_];
    out_to_ = dead_reckoned_.p;
    logInfo("output re-anchored after ", dead_reckoned_.t - last_output_.t,
            " s of IMU dead reckoning");
  }
  last_output_ = latestState();
  dead_reckoned_ = last_output_;
  have_output_ = true;
  return true;
}

bool Estimator::detectFailure(std::string* why) const {
  auto fail = [&](const std::string& w) {
    *why = w;
    return true;
  };
  if (!Ps_[W_].allFinite() || !Vs_[W_].allFinite() || !Rs_[W_].allFinite())
    return fail("the solution is not finite");
  if (Bas_[W_].norm() > options_.max_accel_bias)
    return fail("accelerometer bias estimate " + std::to_string(Bas_[W_].norm()) +
                " m/s^2 too large");
  if (Bgs_[W_].norm() > options_.max_gyro_bias)
    return fail("gyroscope bias estimate " + std::to_string(Bgs_[W_].norm()) + " rad/s too large");
  if ((Ps_[W_] - last_P_).norm() > options_.max_translation_jump_m)
    return fail("position jumped " + std::to_string((Ps_[W_] - last_P_).norm()) +
                " m in one frame");
  if (std::abs(Ps_[W_].z() - last_P_.z()) > options_.max_z_jump_m)
    return fail("height jumped " + std::to_string(std::abs(Ps_[W_].z() - last_P_.z())) +
                " m in one frame");
  const double angle = Eigen::AngleAxisd(last_R_.transpose() * Rs_[W_]).angle() * kRadToDeg;
  if (angle > options_.max_rotation_jump_deg)
    return fail("rotation jumped " + std::to_string(angle) + " deg in one frame");
  return false;
}

void Estimator::reset(double t, const std::string& why) {
  ++reset_count_;
  logWarn("estimator failure at t=", stampText(t), ": ", why, "; resetting and re-initialising");
  event(EstimatorEvent::Kind::kFailure, t, why);
  // Keep the latest biases: they are still the best guess after a reset.
  const Eigen::Vector3d ba = Bas_[W_], bg = Bgs_[W_];
  clearState();
  for (int i = 0; i <= W_; ++i) {
    Bas_[i] = ba.allFinite() && ba.norm() < options_.max_accel_bias ? ba : Eigen::Vector3d::Zero();
    Bgs_[i] = bg.allFinite() && bg.norm() < options_.max_gyro_bias ? bg : Eigen::Vector3d::Zero();
  }
  align_output_after_reset_ = have_output_;
  warm_restart_armed_ = have_output_ && options_.warm_restart_max_s > 0;
  event(EstimatorEvent::Kind::kReset, t, "reset: " + why);
}

void Estimator::initialized(double t) {
  EstimatorEvent e;
  e.kind = EstimatorEvent::Kind::kInitialized;
  e.t = t;
  e.window = windowStates();
  e.scale = init_scale_;
  e.message = warm_started_ ? "initialised again from IMU dead reckoning" : "initialised";
  events_.push_back(std::move(e));
}

void Estimator::rememberSettlingWindow() {
  settling_positions_.clear();
  for (int i = 0; i <= W_; ++i) settling_positions_[header_ns_[i]] = Ps_[i];
}

double Estimator::windowScaleChange() const {
  // The distance between the oldest and the newest frame both optimisations hold.
  int first = -1, last = -1;
  for (int i = 0; i <= W_; ++i) {
    if (!settling_positions_.count(header_ns_[i])) continue;
    if (first < 0) first = i;
    last = i;
  }
  if (first < 0 || last == first) return std::numeric_limits<double>::infinity();
  const double before =
      (settling_positions_.at(header_ns_[last]) - settling_positions_.at(header_ns_[first])).norm();
  const double now = (Ps_[last] - Ps_[first]).norm();
  if (before < 1e-3) return std::numeric_limits<double>::infinity();
  return std::abs(now / before - 1);
}

void Estimator::slideWindow() {
  if (marginalization_ == Marginalization::kOld) {
    const double t0 = headers_[0];
    const int64_t t0_exact_ns = header_ns_[0];
    const Eigen::Isometry3d T_w_c0 = cameraPose(t0_exact_ns);
    back_R0_ = Rs_[0];
    back_P0_ = Ps_[0];
    if (frame_count_ == W_) {
      if (options_.record_analysis && status_ == EstimatorStatus::kTracking) recordWindow();
      for (int i = 0; i < W_; ++i) {
        headers_[i] = headers_[i + 1];
        intensity_[i] = intensity_[i + 1];
        header_ns_[i] = header_ns_[i + 1];
        Ps_[i] = Ps_[i + 1];
        Vs_[i] = Vs_[i + 1];
        Rs_[i] = Rs_[i + 1];
        Bas_[i] = Bas_[i + 1];
        Bgs_[i] = Bgs_[i + 1];
        std::swap(preintegrations_[i], preintegrations_[i + 1]);
        std::swap(dt_buf_[i], dt_buf_[i + 1]);
        std::swap(acc_buf_[i], acc_buf_[i + 1]);
        std::swap(gyr_buf_[i], gyr_buf_[i + 1]);
      }
      // The newest slot continues from the newest state.
      preintegrations_[W_] =
          std::make_unique<ImuPreintegration>(acc_0_, gyr_0_, Bas_[W_], Bgs_[W_], imuNoise());
      dt_buf_[W_].clear();
      acc_buf_[W_].clear();
      gyr_buf_[W_].clear();
      // Frames older than the new oldest keyframe are no longer needed for initialisation.
      // (1 us of slack: t0 went through double seconds and lost a few ns.)
      const int64_t t0_ns = secToNs(t0) + 1000;
      all_frames_.erase(all_frames_.begin(), all_frames_.upper_bound(t0_ns));
      // Before initialisation the window's poses are placeholders, unfit for the map.
      lines_.removeFrame(t0_exact_ns, status_ == EstimatorStatus::kTracking ? &T_w_c0 : nullptr);
      if (status_ == EstimatorStatus::kTracking) {
        const Eigen::Matrix3d R_c_old = back_R0_ * T_b_c_.linear();
        const Eigen::Vector3d p_c_old = back_P0_ + back_R0_ * T_b_c_.translation();
        const Eigen::Matrix3d R_c_new = Rs_[0] * T_b_c_.linear();
        const Eigen::Vector3d p_c_new = Ps_[0] + Rs_[0] * T_b_c_.translation();
        points_.removeOldestShiftDepth(R_c_old, p_c_old, R_c_new, p_c_new);
      } else {
        points_.removeOldest();
      }
    }
  } else if (frame_count_ == W_) {
    // Drop the second-newest frame: its IMU data joins the newest frame's interval.
    for (std::size_t k = 0; k < dt_buf_[W_].size(); ++k) {
      preintegrations_[W_ - 1]->push(dt_buf_[W_][k], acc_buf_[W_][k], gyr_buf_[W_][k]);
      dt_buf_[W_ - 1].push_back(dt_buf_[W_][k]);
      acc_buf_[W_ - 1].push_back(acc_buf_[W_][k]);
      gyr_buf_[W_ - 1].push_back(gyr_buf_[W_][k]);
    }
    const Eigen::Isometry3d T_w_c = cameraPose(header_ns_[W_ - 1]);
    lines_.removeFrame(header_ns_[W_ - 1],
                       status_ == EstimatorStatus::kTracking ? &T_w_c : nullptr);
    headers_[W_ - 1] = headers_[W_];
    header_ns_[W_ - 1] = header_ns_[W_];
    intensity_[W_ - 1] = intensity_[W_];
    Ps_[W_ - 1] = Ps_[W_];
    Vs_[W_ - 1] = Vs_[W_];
    Rs_[W_ - 1] = Rs_[W_];
    Bas_[W_ - 1] = Bas_[W_];
    Bgs_[W_ - 1] = Bgs_[W_];
    preintegrations_[W_] =
        std::make_unique<ImuPreintegration>(acc_0_, gyr_0_, Bas_[W_], Bgs_[W_], imuNoise());
    dt_buf_[W_].clear();
    acc_buf_[W_].clear();
    gyr_buf_[W_].clear();
    points_.removeSecondNewest(frame_count_);
  }
}

BodyState Estimator::toOutput(const BodyState& s) const {
  const Eigen::Matrix3d Rz =
      Eigen::AngleAxisd(out_yaw_, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  BodyState o = s;
  o.p = Rz * (s.p - out_from_) + out_to_;
  o.q = Eigen::Quaterniond(Rz * s.q.toRotationMatrix()).normalized();
  o.v = Rz * s.v;
  return o;
}

BodyState Estimator::fromOutput(const BodyState& o) const {
  const Eigen::Matrix3d Rz_t =
      Eigen::AngleAxisd(-out_yaw_, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  BodyState s = o;
  s.p = Rz_t * (o.p - out_to_) + out_from_;
  s.q = Eigen::Quaterniond(Rz_t * o.q.toRotationMatrix()).normalized();
  s.v = Rz_t * o.v;
  return s;
}

void Estimator::seedFromDeadReckoning(double t) {
  // The dead-reckoned state is at the time of the IMU fed last: this frame's, unless the IMU
  // stopped before it.
  if (!have_output_ || std::abs(dead_reckoned_.t - t) > 1e-3) return;
  const BodyState s = fromOutput(dead_reckoned_);
  Ps_[0] = s.p;
  Vs_[0] = s.v;
  Rs_[0] = s.q.toRotationMatrix();
  Bas_[0] = s.ba;
  Bgs_[0] = s.bg;
  warm_seeded_ = true;
}

BodyState Estimator::latestState() const {
  BodyState s;
  s.t = headers_[frame_count_];
  s.p = Ps_[frame_count_];
  s.q = Eigen::Quaterniond(Rs_[frame_count_]).normalized();
  s.v = Vs_[frame_count_];
  s.ba = Bas_[frame_count_];
  s.bg = Bgs_[frame_count_];
  return toOutput(s);
}

std::vector<BodyState, Eigen::aligned_allocator<BodyState>> Estimator::windowStates() const {
  std::vector<BodyState, Eigen::aligned_allocator<BodyState>> out;
  for (int i = 0; i <= frame_count_; ++i) {
    BodyState s;
    s.t = headers_[i];
    s.p = Ps_[i];
    s.q = Eigen::Quaterniond(Rs_[i]).normalized();
    s.v = Vs_[i];
    s.ba = Bas_[i];
    s.bg = Bgs_[i];
    out.push_back(toOutput(s));
  }
  return out;
}

Eigen::Isometry3d Estimator::cameraPose(int64_t frame_ns) const {
  for (int i = 0; i <= frame_count_; ++i)
    if (header_ns_[i] == frame_ns) {
      Eigen::Isometry3d T_w_b = Eigen::Isometry3d::Identity();
      T_w_b.linear() = Rs_[i];
      T_w_b.translation() = Ps_[i];
      return T_w_b * T_b_c_;
    }
  throw Error("estimator: no window frame at " + std::to_string(frame_ns) + " ns");
}

LineSegments3 Estimator::lineSegments(double max_direction_std_deg) const {
  LineSegments3 out;
  if (status_ != EstimatorStatus::kTracking) return out;
  for (const auto& [id, l] : lines_.landmarks()) {
    if (!lines_.usable(l) || !l.has_extent) continue;
    if (max_direction_std_deg > 0 &&
        (l.direction_std_deg < 0 || l.direction_std_deg > max_direction_std_deg))
      continue;
    LineSegment3 seg;
    seg.id = id;
    BodyState a, b;
    a.p = l.start_w;
    b.p = l.end_w;
    seg.start = toOutput(a).p;
    seg.end = toOutput(b).p;
    seg.observations = static_cast<int>(l.observations.size());
    seg.direction_std_deg = l.direction_std_deg;
    out.push_back(seg);
  }
  return out;
}

void Estimator::recordWindow() {
  WindowTrackRecord r;
  r.t = headers_[0];
  r.frames = frame_count_ + 1;
  for (int i = 0; i <= frame_count_; ++i) r.mean_intensity += intensity_[i] / r.frames;
  r.motion_m = (Ps_[frame_count_] - Ps_[0]).cwiseAbs().sum();
  for (const auto& [id, l] : points_.landmarks()) {
    if (l.start_frame != 0) continue;
    r.points.push_back({id, l.sightings.front().px, static_cast<int>(l.sightings.size())});
  }
  const double fx = camera_.intrinsics[0], fy = camera_.intrinsics[1];
  const double cx = camera_.intrinsics[2], cy = camera_.intrinsics[3];
  for (const auto& [id, l] : lines_.landmarks()) {
    const auto first = l.observations.find(header_ns_[0]);
    if (first == l.observations.end()) continue;
    const Eigen::Vector2d mid = 0.5 * (first->second.start_norm + first->second.end_norm);
    r.lines.push_back({id, Eigen::Vector2d(fx * mid.x() + cx, fy * mid.y() + cy),
                       static_cast<int>(l.observations.size())});
  }
  window_records_.push_back(std::move(r));
}

std::vector<WindowTrackRecord> Estimator::takeWindowRecords() {
  std::vector<WindowTrackRecord> out;
  out.swap(window_records_);
  return out;
}

LineSegments3 Estimator::takeRetiredLines() {
  LineSegments3 out;
  for (const LineLandmark& l : lines_.takeRetired()) {
    LineSegment3 seg;
    seg.id = l.id;
    BodyState a, b;
    a.p = l.start_w;
    b.p = l.end_w;
    seg.start = toOutput(a).p;
    seg.end = toOutput(b).p;
    seg.direction_std_deg = l.direction_std_deg;
    seg.midpoint_std_m = l.midpoint_std_m;
    seg.observations = l.track_observations;
    out.push_back(seg);
  }
  return out;
}

std::map<int, Eigen::Vector3d> Estimator::landmarkPositions() const {
  std::map<int, Eigen::Vector3d> out;
  if (status_ != EstimatorStatus::kTracking) return out;
  for (const auto& [id, l] : points_.landmarks()) {
    if (!l.usable(W_) || l.depth <= 0) continue;
    const int i = l.start_frame;
    const Eigen::Vector3d p_c = l.sightings.front().xy1 * l.depth;
    BodyState s;
    s.p = Rs_[i] * (T_b_c_ * p_c) + Ps_[i];
    out[id] = toOutput(s).p;
  }
  return out;
}

}  // namespace alvio
