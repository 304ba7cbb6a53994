#pragma once
// Runs the pipeline over a recorded dataset as fast as it can, deterministically,
// with a progress bar, and writes the run's files:
//   trajectory.tum   body pose T_w_b at every frame after initialisation (TUM)
//   timing.csv       per-frame stage times (ms)
//   events.log       initialisation, waiting reasons, failures and resets
//   frame_stats.csv  per frame: features tracked/used, residuals, adaptive weights
//   summary.json     counts, timing summary, initialisation quality and ATE
// The files are written when the run ends, also when it is stopped early (RunOptions::stop).
// and, when the dataset has ground truth, prints the ATE.

#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "alvio/common/timing.h"
#include "alvio/config/config.h"
#include "alvio/estimator/estimator.h"
#include "alvio/eval/trajectory_evaluation.h"
#include "alvio/pipeline/run_observer.h"
#include "alvio/pipeline/sensor_source.h"

namespace alvio {

struct PipelineOutput;

struct RunOptions {
  std::string out_dir;
  bool progress = true;
  int max_frames = -1;  ///< stop after this many images (-1: all)
  /// Skip the data of this many seconds from the first message on (IMU and images): a run
  /// that starts mid-way, as a robot's VIO started while it moves.
  double start_s = 0;
  /// Called with the run's data (not owned; e.g. the MRPT logger). See run_observer.h.
  std::vector<RunObserver*> observers;
  /// When set (e.g. by SIGINT), the run stops after the current frame and still writes
  /// every output file and finishes the observers (maps, logs).
  const std::atomic<bool>* stop = nullptr;
};

struct InitializationQuality {
  double time = 0;                ///< when it initialised (s, dataset time)
  double since_motion_s = -1;     ///< after the first motion in the ground truth (or the start)
  double scale_error = -1;        ///< |s - 1| of the window positions vs ground truth
  double gravity_error_deg = -1;  ///< mean roll/pitch error of the window
};

struct RunResult {
  std::size_t frames = 0, poses = 0, skipped_images = 0;
  /// Messages dropped as out of order (stamp not after the previous one) or not finite.
  std::size_t dropped_images = 0, dropped_imu = 0;
  int resets = 0;
  bool interrupted = false;  ///< stopped early by RunOptions::stop
  Trajectory trajectory;
  TimingLog timing;
  std::optional<InitializationQuality> initialization;
  std::optional<EvaluationResult> evaluation;  ///< SE(3) ATE, when ground truth exists
  double observer_ms = 0;                ///< wall time spent in observers' onStart/onImu/onFrame
  LineRetirementCounts line_retirement;  ///< lines handed to the maps or held back
  /// estimator.estimate_time_shift: the estimate at the end, on top of camera.timeshift_cam_imu.
  std::optional<double> estimated_time_shift_s;
};

RunResult runOffline(SensorSource& source, const Config& config, const RunOptions& options);

/// Initialisation quality of `window` against ground truth `gt` (positions, roll/pitch).
InitializationQuality initializationQuality(
    const std::vector<BodyState, Eigen::aligned_allocator<BodyState>>& window,
    const Trajectory& gt);

}  // namespace alvio
