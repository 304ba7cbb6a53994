#include "alvio/pipeline/offline_runner.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "alvio/common/angles.h"
#include "alvio/common/clock_jump.h"
#include "alvio/common/error.h"
#include "alvio/common/logging.h"
#include "alvio/common/progress_bar.h"
#include "alvio/eval/evaluation_report.h"
#include "alvio/io/trajectory_io.h"
#include "alvio/pipeline/vio_pipeline.h"

namespace alvio {

namespace {

// Nearest ground-truth pose (within 20 ms) to time t.
const StampedPose* nearestPose(const Trajectory& gt, double t) {
  auto it = std::lower_bound(gt.begin(), gt.end(), t,
                             [](const StampedPose& p, double v) { return p.t < v; });
  const StampedPose* best = nullptr;
  for (auto c : {it, it == gt.begin() ? it : std::prev(it)})
    if (c != gt.end() && (!best || std::abs(c->t - t) < std::abs(best->t - t))) best = &*c;
  return best && std::abs(best->t - t) < 0.02 ? best : nullptr;
}

// First time the ground truth moves faster than 0.1 m/s or turns faster than 10 deg/s.
double firstMotion(const Trajectory& gt) {
  for (std::size_t i = 10; i < gt.size(); i += 10) {
    const double dt = gt[i].t - gt[i - 10].t;
    if (dt <= 0) continue;
    const double v = (gt[i].p - gt[i - 10].p).norm() / dt;
    const double w = gt[i].q.angularDistance(gt[i - 10].q) / dt;
    if (v > 0.1 || w > 10.0 * kDegToRad) return gt[i - 10].t;
  }
  return gt.empty() ? 0 : gt.front().t;
}

std::string eventKindName(EstimatorEvent::Kind k) {
  switch (k) {
    case EstimatorEvent::Kind::kWaiting:
      return "waiting";
    case EstimatorEvent::Kind::kInitialized:
      return "initialized";
    case EstimatorEvent::Kind::kFailure:
      return "failure";
    case EstimatorEvent::Kind::kReset:
      return "reset";
  }
  return "?";
}

}  // namespace

InitializationQuality initializationQuality(
    const std::vector<BodyState, Eigen::aligned_allocator<BodyState>>& window,
    const Trajectory& gt) {
  InitializationQuality q;
  Points3 est, truth;
  double gravity_err = 0;
  int n = 0;
  for (const auto& s : window) {
    const StampedPose* g = nearestPose(gt, s.t);
    if (!g) continue;
    est.push_back(s.p);
    truth.push_back(g->p);
    // Gravity direction in the body frame, estimated vs true.
    const Eigen::Vector3d z_est = s.q.inverse() * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d z_gt = g->q.inverse() * Eigen::Vector3d::UnitZ();
    gravity_err += std::acos(std::clamp(z_est.dot(z_gt), -1.0, 1.0)) * kRadToDeg;
    ++n;
  }
  if (n >= 3) {
    q.scale_error = std::abs(alignPoints(est, truth, AlignmentMode::kSim3).s - 1.0);
    q.gravity_error_deg = gravity_err / n;
  }
  return q;
}

RunResult runOffline(SensorSource& source, const Config& config, const RunOptions& options) {
  namespace fs = std::filesystem;
  fs::create_directories(options.out_dir);
  VioPipeline pipeline(config);
  RunResult result;
  const auto gt = source.groundTruth();
  std::ostringstream events_log;
  std::ostringstream frame_stats;
  frame_stats
      << "t,points,lines,points_tracked,lines_tracked,points_used,lines_used,point_residuals,"
         "line_residuals,w_p,w_l,alpha,iterations,unsuccessful_steps,solver_ms,linear_solver_ms,"
         "jacobian_ms\n";
  // The newest state as estimated when its frame arrived: whether the IMU biases settle.
  std::ostringstream states;
  states << "t,vx,vy,vz,bax,bay,baz,bgx,bgy,bgz,time_shift_s\n";
  if (!(options.start_s >= 0))
    throw Error("start must be >= 0 s, got " + std::to_string(options.start_s));
  // The images left after the start, as the camera's rate counts them (for the progress bar).
  const std::size_t skipped_estimate = std::min<std::size_t>(
      source.imageCount(), static_cast<std::size_t>(options.start_s * config.camera.rate_hz));
  const std::size_t after_start = source.imageCount() - skipped_estimate;
  const std::size_t total =
      options.max_frames > 0 ? std::min<std::size_t>(options.max_frames, after_start) : after_start;
  ProgressBar progress("alvio run", total, options.progress);

  // Each observer's time goes to its stage; IMU-time work waits for the next frame's row.
  std::vector<double> observer_stage_ms(options.observers.size(), 0.0);
  auto notify = [&](auto&& call) {
    for (std::size_t i = 0; i < options.observers.size(); ++i) {
      const auto start = std::chrono::steady_clock::now();
      call(*options.observers[i]);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count();
      observer_stage_ms[i] += ms;
      result.observer_ms += ms;
    }
  };
  const RunInfo info{config, source.description(), options.out_dir, gt ? &*gt : nullptr};
  notify([&](RunObserver& o) { o.onStart(info); });
  std::fill(observer_stage_ms.begin(), observer_stage_ms.end(), 0.0);  // not a frame's work

  // An image waits until an IMU sample after it has arrived, so the estimator can
  // interpolate the IMU at the image time.
  std::deque<SensorMessage> pending;
  // The first message's time and the first one kept after options.start_s (0: from the start).
  int64_t first_ns = -1, start_ns = 0;
  auto processImage = [&](const SensorMessage& m) {
    const cv::Mat image = m.load_image();
    if (image.empty()) {
      ++result.skipped_images;
      logWarn("image at ", m.t_ns, " ns could not be read: skipped");
      return;
    }
    if (image.cols != config.camera.width || image.rows != config.camera.height) {
      const std::string size = std::to_string(image.cols) + "x" + std::to_string(image.rows);
      const std::string key = config.source + ": key 'camera.resolution' is [" +
                              std::to_string(config.camera.width) + ", " +
                              std::to_string(config.camera.height) + "]";
      // The first image decides: a mismatch there is a wrong config, not a bad frame.
      if (result.frames == 0)
        throw Error(key + " but the dataset's images are " + size + " (image at " +
                    std::to_string(m.t_ns) + " ns)");
      ++result.skipped_images;
      logWarn("image at ", m.t_ns, " ns is ", size, " (", key, "): skipped");
      return;
    }
    PipelineOutput out = pipeline.addImage(image, m.t_ns);
    if (out.dropped) return;
    ++result.frames;
    for (const auto& e : out.events) {
      events_log << std::fixed << e.t << " " << eventKindName(e.kind) << " " << e.message << "\n";
      if (e.kind == EstimatorEvent::Kind::kInitialized && gt && !result.initialization) {
        InitializationQuality q = initializationQuality(e.window, *gt);
        q.time = e.t;
        q.since_motion_s = e.t - std::max(firstMotion(*gt), nsToSec(start_ns));
        result.initialization = q;
      }
    }
    if (out.has_pose) {
      const OptimizationStats& o = out.optimization;
      char row[256];
      std::snprintf(row, sizeof(row),
                    "%.6f,%zu,%zu,%d,%d,%d,%d,%d,%d,%.4f,%.4f,%.2f,%d,%d,%.3f,%.3f,%.3f\n",
                    out.state.t, out.features.points.size(), out.features.lines.size(),
                    o.points_tracked, o.lines_tracked, o.points_used, o.lines_used,
                    o.point_residuals, o.line_residuals, o.w_p, o.w_l, o.alpha, o.iterations,
                    o.unsuccessful_steps, o.solver_ms, o.linear_solver_ms, o.jacobian_ms);
      frame_stats << row;
      const BodyState& x = out.state;
      std::snprintf(row, sizeof(row), "%.6f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.6f,%.6f,%.6f,%.6f\n",
                    x.t, x.v.x(), x.v.y(), x.v.z(), x.ba.x(), x.ba.y(), x.ba.z(), x.bg.x(),
                    x.bg.y(), x.bg.z(), pipeline.estimator().timeShift());
      states << row;
      StampedPose p;
      p.t = out.state.t;
      p.p = out.state.p;
      p.q = out.state.q;
      result.trajectory.push_back(p);
    }
    notify([&](RunObserver& o) { o.onFrame(FrameView{m.t_ns, image, out, pipeline}); });
    FrameTiming timing = out.timing;
    for (std::size_t i = 0; i < options.observers.size(); ++i) {
      timing.add(options.observers[i]->stage(), observer_stage_ms[i]);
      observer_stage_ms[i] = 0;
    }
    result.timing.add(timing);
    progress.update(result.frames + result.skipped_images,
                    out.has_pose ? "tracking" : "initialising");
  };

  const auto stopRequested = [&] { return options.stop && options.stop->load(); };
  SensorMessage m;
  std::size_t images_seen = 0, images_of_old_clock = 0;
  bool started = options.start_s <= 0;
  while (!stopRequested() && source.next(&m)) {
    // Images come stamped on the camera's clock; the pipeline runs on the IMU's.
    if (m.kind == SensorMessage::Kind::kImage) {
      m.t_ns = config.camera.imuClockNs(m.t_ns);
      // A camera stamped late by the shift, on a clock that starts at 0 (simulated time).
      if (m.t_ns <= 0) {
        ++result.skipped_images;
        logWarn("image at ", m.t_ns, " ns on the IMU's clock (camera.timeshift_cam_imu): skipped");
        continue;
      }
    }
    if (!started) {
      if (first_ns < 0) first_ns = m.t_ns;
      if (m.t_ns < first_ns + secToNs(options.start_s)) continue;
      started = true;
      start_ns = m.t_ns;
    }
    if (m.kind == SensorMessage::Kind::kImu) {
      if (pipeline.addImu(m.imu)) {
        // Images of the old clock still waiting for IMU: none will come after them.
        const auto old_clock = [&](const SensorMessage& p) {
          return clockJumpedBack(m.t_ns, p.t_ns);
        };
        images_of_old_clock += std::count_if(pending.begin(), pending.end(), old_clock);
        pending.erase(std::remove_if(pending.begin(), pending.end(), old_clock), pending.end());
      }
      notify([&](RunObserver& o) { o.onImu(m.imu); });
      while (!pending.empty() && pending.front().t_ns < m.t_ns && !stopRequested()) {
        processImage(pending.front());
        pending.pop_front();
      }
      continue;
    }
    if (options.max_frames > 0 && images_seen >= static_cast<std::size_t>(options.max_frames))
      break;
    ++images_seen;
    pending.push_back(m);
  }
  // Images still waiting for IMU are dropped on a stop: stopping promptly matters more.
  result.interrupted = stopRequested();
  if (!result.interrupted)
    for (const auto& p : pending) processImage(p);
  progress.finish(result.interrupted
                      ? "(stopped early after " +
                            std::to_string(result.frames + result.skipped_images) + ")"
                      : "");
  if (result.interrupted) logWarn("run stopped early: writing the results so far");
  result.resets = pipeline.estimator().resetCount();
  result.dropped_images = pipeline.droppedImages() + images_of_old_clock;
  result.dropped_imu = pipeline.estimator().droppedImu();
  result.line_retirement = pipeline.estimator().lineRetirementCounts();
  result.poses = result.trajectory.size();
  if (config.estimator.estimate_time_shift)
    result.estimated_time_shift_s = pipeline.estimator().timeShift();

  writeTumTrajectory((fs::path(options.out_dir) / "trajectory.tum").string(), result.trajectory);
  writeFileAtomically((fs::path(options.out_dir) / "timing.csv").string(), result.timing.toCsv());
  writeFileAtomically((fs::path(options.out_dir) / "events.log").string(), events_log.str());
  writeFileAtomically((fs::path(options.out_dir) / "frame_stats.csv").string(), frame_stats.str());
  writeFileAtomically((fs::path(options.out_dir) / "states.csv").string(), states.str());

  nlohmann::json summary;
  summary["dataset"] = source.description();
  summary["config"] = config.source;
  summary["frames"] = result.frames;
  summary["poses"] = result.poses;
  summary["skipped_images"] = result.skipped_images;
  summary["dropped_images"] = result.dropped_images;
  summary["dropped_imu"] = result.dropped_imu;
  summary["resets"] = result.resets;
  summary["lines_retired"] = result.line_retirement.retired;
  summary["lines_held_back_fit"] = result.line_retirement.held_back_fit;
  summary["lines_held_back_parallax"] = result.line_retirement.held_back_parallax;
  summary["lines_held_back_edge"] = result.line_retirement.held_back_edge;
  summary["lines_held_back_uncertain"] = result.line_retirement.held_back_uncertain;
  summary["interrupted"] = result.interrupted;
  if (result.estimated_time_shift_s) {
    summary["estimated_time_shift_s"] = *result.estimated_time_shift_s;
    summary["timeshift_cam_imu_s"] =
        config.camera.timeshift_cam_imu + *result.estimated_time_shift_s;
  }
  for (const auto& s : result.timing.summary())
    summary["timing_ms"][s.stage] = {
        {"median", s.median_ms}, {"p95", s.p95_ms}, {"max", s.max_ms}, {"mean", s.mean_ms}};
  if (result.initialization) {
    const auto& q = *result.initialization;
    summary["initialization"] = {{"time", q.time},
                                 {"since_first_motion_s", q.since_motion_s},
                                 {"scale_error", q.scale_error},
                                 {"gravity_error_deg", q.gravity_error_deg}};
  }
  if (gt && result.trajectory.size() >= 3) {
    EvaluationOptions eo;
    try {
      result.evaluation = evaluateTrajectory(result.trajectory, *gt, eo);
      summary["ate_rmse_m"] = result.evaluation->ate_translation_m.rmse;
      writeFileAtomically(
          (fs::path(options.out_dir) / "eval.json").string(),
          evaluationToJson(*result.evaluation, eo, "dataset ground truth", "trajectory.tum"));
    } catch (const Error& e) {
      logWarn("evaluation failed: ", e.what());
    }
  }
  writeFileAtomically((fs::path(options.out_dir) / "summary.json").string(),
                      summary.dump(2) + "\n");
  notify([&](RunObserver& o) { o.onFinish(result); });
  return result;
}

}  // namespace alvio
