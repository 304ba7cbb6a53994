#pragma once
// The MRPT logger attached to the offline runner (RunObserver): it writes
// <name>.rawlog, <name>_Images/, <name>.3Dscene and alvio.log into the run's
// output folder, and tees the core's log messages (alvio::logMessage) into the
// text log for the duration of the run, keeping their usual output.

#include <functional>
#include <memory>

#include "alvio/config/logger_options.h"
#include "alvio/logging/mrpt_logger.h"
#include "alvio/pipeline/run_observer.h"

namespace alvio {

class Estimator;

class RunLogger : public RunObserver {
 public:
  /// Where 3D line segments for the scenes come from (the line map, once there is one);
  /// called only when a scene is written.
  using LineSource = std::function<SceneSegments(const VioPipeline&)>;

  explicit RunLogger(const LoggerOptions& options);
  /// Finishes the files and restores the log sink if the run did not finish (exception).
  ~RunLogger() override;

  /// Where the scene's 3D lines come from (default: the estimator's window lines).
  void setLineSource(LineSource source) { line_source_ = std::move(source); }
  /// The logger of the current/last run; nullptr before onStart.
  const MrptLogger* logger() const { return logger_.get(); }

  void onStart(const RunInfo& info) override;
  void onImu(const ImuSample& sample) override;
  void onFrame(const FrameView& frame) override;
  std::string stage() const override { return "logging"; }
  void onFinish(const RunResult& result) override;

  /// The estimator's map in the output world frame (empty before initialisation).
  static MapSnapshot snapshot(const Estimator& estimator);

 private:
  void restoreLogSink();
  MapSnapshot snapshotOf(const VioPipeline& pipeline) const;

  LoggerOptions options_;
  LineSource line_source_;
  std::unique_ptr<MrptLogger> logger_;
  Trajectory ground_truth_;
  std::size_t next_ground_truth_ = 0;
  const VioPipeline* pipeline_ = nullptr;  // valid from the first onFrame to onFinish
  bool sink_installed_ = false;
  LogSink previous_sink_;
};

}  // namespace alvio
