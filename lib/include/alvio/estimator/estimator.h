#pragma once
// The tightly coupled sliding-window visual-inertial estimator (VINS-Mono
// style): IMU preintegration between keyframes, inverse-depth point landmarks,
// a Ceres optimisation per frame, marginalisation of the oldest keyframe (or
// dropping of the second-newest frame), initialisation by visual SfM plus
// visual-inertial alignment, failure detection and reset.
//
// Implementation is split by responsibility: estimator.cpp (frame flow, IMU,
// sliding, failure handling), estimator_optimization.cpp (the Ceres problem
// and marginalisation), estimator_initialization.cpp (SfM + alignment).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "alvio/common/log_throttle.h"
#include "alvio/common/timing.h"
#include "alvio/common/types.h"
#include "alvio/config/sensor_options.h"
#include "alvio/estimator/estimator_options.h"
#include "alvio/estimator/line_landmarks.h"
#include "alvio/estimator/point_landmarks.h"
#include "alvio/frontend/feature_frame.h"
#include "alvio/imu/imu_preintegration.h"

namespace alvio {

class LineProjectionFactor;
class MarginalizationInfo;
class PointProjectionFactor;

enum class EstimatorStatus { kInitializing, kTracking };

/// The body state of one frame, in the output world frame (see Estimator).
struct BodyState {
  double t = 0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Vector3d ba = Eigen::Vector3d::Zero();
  Eigen::Vector3d bg = Eigen::Vector3d::Zero();
  /// The body pose in the world frame.
  Eigen::Isometry3d T_w_b() const { return isometry(p, q); }
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// A 3D line landmark of the window, in the output world frame.
struct LineSegment3 {
  int id = -1;
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  Eigen::Vector3d end = Eigen::Vector3d::Zero();
  int observations = 0;           ///< in the window (0 for retired lines)
  double direction_std_deg = -1;  ///< 1-sigma direction uncertainty
  double midpoint_std_m = -1;     ///< retired lines: 1-sigma midpoint uncertainty across the line
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};
using LineSegments3 = std::vector<LineSegment3, Eigen::aligned_allocator<LineSegment3>>;

/// Tracking statistics of one sliding window, for the sensitivity analysis (ALVIO Sec. 3):
/// every feature seen in the window's first frame, where it was, and in how many of the
/// window's frames it was tracked; the window's illumination and motion.
struct WindowTrackRecord {
  struct Feature {
    int id = -1;
    Eigen::Vector2d px = Eigen::Vector2d::Zero();  ///< in the first frame (lines: midpoint)
    int tracked_frames = 0;                        ///< window frames that observe it
  };
  double t = 0;               ///< time of the window's first frame
  int frames = 0;             ///< frames in the window
  double mean_intensity = 0;  ///< average pixel value over the window's frames
  double motion_m = 0;        ///< sum of |dx|+|dy|+|dz| between first and last frame
  std::vector<Feature> points, lines;
};

/// What the last optimisation used (diagnostics, the ablation and Fig. 8 plots).
struct OptimizationStats {
  int points_tracked = 0, lines_tracked = 0;  ///< usable landmarks in the window
  int points_used = 0, lines_used = 0;        ///< after selection
  int point_residuals = 0, line_residuals = 0;
  double w_p = 0.5, w_l = 0.5, alpha = 1.0, M_p = 0, M_l = 0;
  int iterations = 0;
  int unsuccessful_steps = 0;  ///< iterations whose step Ceres rejected (the cost rose)
  int accepted_steps = 0;      ///< iterations whose step Ceres took
  /// Ceres's own clock for the solve: total, and its linear solver and Jacobian parts.
  double solver_ms = 0, linear_solver_ms = 0, jacobian_ms = 0;
  /// The Schur eliminator Ceres used, as residual rows, landmark size, pose size ("2,d,d";
  /// "d,d,d" is its slowest, all-dynamic one).
  std::string schur_structure;
};

/// Something a user should know about: initialisation, a reset, why it waits.
struct EstimatorEvent {
  enum class Kind { kWaiting, kInitialized, kFailure, kReset };
  double t = 0;
  Kind kind = Kind::kWaiting;
  std::string message;
  /// For kInitialized: the window's body states right after initialisation.
  std::vector<BodyState, Eigen::aligned_allocator<BodyState>> window;
  double scale = 0;  ///< visual-inertial alignment scale (kInitialized)
};

class Estimator {
 public:
  Estimator(const EstimatorOptions& options, const CameraOptions& camera, const ImuOptions& imu);
  ~Estimator();

  /// Queue an IMU sample (time-ordered; older or duplicate stamps are dropped with a warning).
  /// A stamp over kClockJumpBackNs before the newest is a clock jump: the estimator resets
  /// and continues on the new clock (clockJumps() counts them).
  void addImu(const ImuSample& sample);
  /// Process a frame. IMU up to its time (and one sample after, for interpolation) should be
  /// queued. Returns true when the frame has a pose estimate (after initialisation).
  bool addFrame(const FeatureFrame& frame, FrameTiming* timing = nullptr);

  /// Initialising until the scale has settled after alignment (see init_settle_change).
  EstimatorStatus status() const { return settling_ ? EstimatorStatus::kInitializing : status_; }
  /// State of the newest frame, in the output world frame.
  BodyState latestState() const;
  /// The gyroscope at the newest frame's time: interpolated between the samples around it,
  /// or the last one held when the next has not come. Less bg, the body's angular rate.
  const Eigen::Vector3d& gyroAtLatestFrame() const { return gyr_0_; }
  /// Keyframe states of the window, oldest first, in the output world frame.
  std::vector<BodyState, Eigen::aligned_allocator<BodyState>> windowStates() const;
  /// Triangulated landmarks in the output world frame, by id.
  std::map<int, Eigen::Vector3d> landmarkPositions() const;
  /// Line landmarks used by the optimisation, with their observed extents (output frame).
  /// With `max_direction_std_deg` > 0 only lines whose direction is that well constrained.
  LineSegments3 lineSegments(double max_direction_std_deg = -1) const;
  /// Lines that left the window since the last call, each refined over its whole track
  /// with the final poses of every frame that saw it (for maps). Output frame.
  LineSegments3 takeRetiredLines();
  /// Retired lines handed to the maps and held back by the map filter, since construction.
  const LineRetirementCounts& lineRetirementCounts() const { return lines_.retirementCounts(); }
  int resetCount() const { return reset_count_; }
  /// IMU clock jumps back seen by addImu (each also counted as a reset).
  int clockJumps() const { return clock_jumps_; }
  /// IMU samples dropped by addImu: not after the previous one, or not finite.
  std::size_t droppedImu() const { return imu_late_.total() + imu_nonfinite_.total(); }
  /// Window records since the last call (only when options.record_analysis).
  std::vector<WindowTrackRecord> takeWindowRecords();
  /// Events since the last call (moved out).
  std::vector<EstimatorEvent> takeEvents();
  /// Residual blocks, iterations and Ceres times of the last optimisation (diagnostics).
  const OptimizationStats& lastOptimizationStats() const { return stats_; }
  const PointLandmarks& points() const { return points_; }
  const LineLandmarks& lines() const { return lines_; }
  /// The estimated time shift [s] on top of camera.timeshift_cam_imu (0 unless
  /// options.estimate_time_shift): an image stamped t was taken at t + timeShift(). Kept
  /// through resets, as a property of the sensors.
  double timeShift() const { return time_shift_; }

 private:
  struct ImageFrame {
    std::map<int, Eigen::Vector3d> xy1;               // observations by landmark id
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // body rotation (SfM frame)
    Eigen::Vector3d T = Eigen::Vector3d::Zero();      // camera position (SfM frame)
    std::unique_ptr<ImuPreintegration> imu;           // from the previous frame
    bool is_keyframe = false;
  };
  enum class Marginalization { kOld, kSecondNew };

  // estimator.cpp
  void clearState();
  void feedImu(double t, const Eigen::Vector3d& acc, const Eigen::Vector3d& gyr);
  void processImu(double dt, const Eigen::Vector3d& acc, const Eigen::Vector3d& gyr);
  void consumeImuUpTo(double t);
  /// More than max_imu_gap_s without IMU before `t`: reset, and integrate afresh from the next
  /// sample.
  void imuMissing(double t, double gap_s);
  void slideWindow();
  bool detectFailure(std::string* why) const;
  void reset(double t, const std::string& why);
  // Settling after initialisation (options_.init_settle_*).
  void initialized(double t);  // the kInitialized event, with the window
  void rememberSettlingWindow();
  double windowScaleChange() const;  // since rememberSettlingWindow(), as a fraction
  BodyState toOutput(const BodyState& s) const;
  BodyState fromOutput(const BodyState& o) const;  // the inverse of toOutput()
  void seedFromDeadReckoning(double t);            // options_.warm_restart_max_s
  void event(EstimatorEvent::Kind kind, double t, const std::string& message);
  ImuNoise imuNoise() const;

  // estimator_optimization.cpp
  /// One solve of the window. With `triangulate_lines` false, lines not yet placed stay out
  /// of it (the initial refinement: see addFrame()).
  void optimize(FrameTiming* timing, int max_iterations, bool triangulate_lines = true);
  void statesToParameters();
  void parametersToStates();
  void marginalize();
  void removeReprojectionOutliers();
  void removeLineOutliers();
  void updateLineUncertainty();
  // Selection and weights (feature_selection.h), fixed per frame by updateWeights().
  bool pointSelected(const PointLandmark& l) const;
  bool lineSelected(const LineLandmark& l) const;
  void updateWeights();
  Eigen::Isometry3d cameraPose(int64_t frame_ns) const;  // T_w_c of a window frame

  // estimator_initialization.cpp
  bool initialize(double t);
  bool initialStructure(double t);
  bool alignWithImu(double t);
  bool warmStart(double t);
  void triangulatePointsAfresh();  // every usable point, from the window's current poses

  EstimatorOptions options_;
  CameraOptions camera_;
  ImuOptions imu_options_;
  Eigen::Isometry3d T_b_c_;
  Eigen::Vector3d gravity_;  // (0, 0, -g)
  int W_;                    // window size

  EstimatorStatus status_ = EstimatorStatus::kInitializing;
  Marginalization marginalization_ = Marginalization::kOld;
  int frame_count_ = 0;

  // Window states, W_ + 1 slots.
  std::vector<double> headers_;
  std::vector<int64_t> header_ns_;  // same, exact
  std::vector<double> intensity_;   // mean image intensity per slot
  std::vector<Eigen::Vector3d> Ps_, Vs_, Bas_, Bgs_;
  std::vector<Eigen::Matrix3d> Rs_;
  std::vector<std::unique_ptr<ImuPreintegration>> preintegrations_;
  std::vector<std::vector<double>> dt_buf_;
  std::vector<std::vector<Eigen::Vector3d>> acc_buf_, gyr_buf_;
  PointLandmarks points_;
  LineLandmarks lines_;

  // Ceres parameter blocks; addresses are stable for the estimator's lifetime.
  std::vector<std::array<double, 7>> para_pose_;
  std::vector<std::array<double, 9>> para_speed_bias_;
  // Landmarks in one buffer: the usable points' inverse depths, then 4 parameters per usable
  // line, in iteration order. Ceres orders a group's blocks by address, so one buffer makes
  // the elimination order (and so the rounding) independent of where the heap put things.
  std::vector<double> para_landmarks_;
  std::size_t num_point_params_ = 0;
  double* inverseDepthBlock(int index) { return &para_landmarks_[index]; }
  double* lineBlock(std::size_t k);
  // Reprojection factors at the current weights, for the window solve and the prior alike:
  // sighting obs_j in window frame j against the anchor obs_i in frame i.
  PointProjectionFactor* newPointFactor(const PointSighting& obs_i, const PointSighting& obs_j,
                                        int i, int j) const;
  LineProjectionFactor* newLineFactor(const LineLandmarkObservation& obs) const;
  std::map<int64_t, int> windowSlots() const;  ///< frame stamp -> index in the window

  /// The time shift is a window parameter when estimated (options_.estimate_time_shift) and
  /// the estimator tracks; its factors then take para_time_shift_ as their last block.
  bool timeShiftEstimated() const;
  double windowTurnRate() const;  ///< RMS of the bias-free gyroscope over the window [rad/s]
  double time_shift_ = 0;
  std::array<double, 1> para_time_shift_{};

  std::shared_ptr<MarginalizationInfo> last_marginalization_;
  std::vector<double*> last_marginalization_blocks_;

  // Frames since the oldest keyframe, for initialisation (by time in ns).
  std::map<int64_t, ImageFrame> all_frames_;
  std::unique_ptr<ImuPreintegration> tmp_preintegration_;

  // IMU stream.
  std::deque<ImuSample> imu_queue_;
  bool has_imu_ = false;
  double imu_time_ = 0;         // time of the last sample fed to processImu
  double last_real_imu_t_ = 0;  ///< the last sample fed, not one held or interpolated
  Eigen::Vector3d acc_0_ = Eigen::Vector3d::Zero(), gyr_0_ = Eigen::Vector3d::Zero();
  int64_t last_queued_imu_ns_ = 0;
  LogThrottle imu_late_, imu_nonfinite_;  // dropped samples, warned about once per 2 s

  double last_init_attempt_ = -1e9;
  double first_moving_attempt_ = -1;    ///< when the relaxed parallax was first seen
  double first_steady_alignment_ = -1;  ///< when init_min_scale_motion_m first held one back
  std::string last_wait_reason_;
  Eigen::Matrix3d last_R_ = Eigen::Matrix3d::Identity(), back_R0_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d last_P_ = Eigen::Vector3d::Zero(), back_P0_ = Eigen::Vector3d::Zero();

  // Output continuity across resets: output = yaw(out_yaw_) * (p - out_from_) + out_to_.
  // The last output state is dead-reckoned with the IMU (in the output frame); after a
  // reset, the re-initialised world frame is anchored on it.
  double out_yaw_ = 0;
  Eigen::Vector3d out_from_ = Eigen::Vector3d::Zero(), out_to_ = Eigen::Vector3d::Zero();
  bool have_output_ = false, align_output_after_reset_ = false;
  BodyState dead_reckoned_;
  BodyState last_output_;
  int reset_count_ = 0;
  int clock_jumps_ = 0;
  double init_scale_ = 0;
  bool bias_prior_pending_ = false;  // the initialisation bias prior is not yet marginalised
  Eigen::Vector3d bias_prior_ba_ = Eigen::Vector3d::Zero(),
                  bias_prior_bg_ = Eigen::Vector3d::Zero();
  // Warm restart: armed by a reset that followed an output; the window's first slot then
  // starts from the dead-reckoned state (seeded), and the others follow by IMU propagation.
  bool warm_restart_armed_ = false, warm_seeded_ = false, warm_started_ = false;
  bool settling_ = false;  ///< initialised, no output until the scale settles
  double settle_start_ = 0;
  std::map<int64_t, Eigen::Vector3d> settling_positions_;  ///< by frame time
  OptimizationStats stats_;
  double point_scale_ = 1.0, line_scale_ = 1.0;  // residual scales from the adaptive weights
  std::vector<EstimatorEvent> events_;
  std::vector<WindowTrackRecord> window_records_;
  void recordWindow();
};

}  // namespace alvio
