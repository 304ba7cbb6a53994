#pragma once
// Hooks into the offline runner for components that record or consume a run
// (the MRPT logger, map builders) without the runner knowing them. Observers
// are called synchronously, in data order, from the runner's thread. Their
// per-frame time (onImu and onFrame) is a stage of its own in timing.csv, named
// by stage(); all of it is also summed in RunResult::observer_ms.

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

#include "alvio/common/types.h"

namespace alvio {

struct Config;
struct PipelineOutput;
struct RunResult;
class VioPipeline;

/// What an observer learns when a run starts.
struct RunInfo {
  const Config& config;
  std::string dataset;             ///< SensorSource::description()
  std::string out_dir;             ///< the run's output folder
  const Trajectory* ground_truth;  ///< nullptr when the dataset has none
};

/// One processed frame: the image as the pipeline saw it, its output, and the pipeline
/// (window states, landmarks) right after the frame.
struct FrameView {
  int64_t t_ns;
  const cv::Mat& image;
  const PipelineOutput& output;
  const VioPipeline& pipeline;
};

class RunObserver {
 public:
  virtual ~RunObserver() = default;
  /// Before the first message.
  virtual void onStart(const RunInfo& info) {}
  /// Every IMU sample, after the pipeline took it.
  virtual void onImu(const ImuSample& sample) {}
  /// Every image the pipeline processed (unreadable images are not reported).
  virtual void onFrame(const FrameView& frame) {}
  /// After the runner wrote its own files (trajectory.tum, summary.json ...).
  virtual void onFinish(const RunResult& result) {}
  /// The timing stage its onImu and onFrame time is reported under ("mapping", "logging").
  virtual std::string stage() const { return "observers"; }
};

}  // namespace alvio
