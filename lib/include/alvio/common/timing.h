#pragma once
// Per-frame stage timing, cheap enough to leave on: a frame's stages are
// recorded as (name, milliseconds) and a run keeps every frame for timing.csv
// and the end-of-run summary (median, p95, max per stage).

#include <chrono>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace alvio {

/// The stage times of one frame.
struct FrameTiming {
  double t = 0;  ///< frame time, seconds
  std::vector<std::pair<std::string, double>> stages_ms;
  void add(const std::string& stage, double ms);
  double total() const;
};

/// Adds the time from construction to destruction (or stop()) to a FrameTiming.
class ScopedStage {
 public:
  ScopedStage(FrameTiming* timing, std::string stage)
      : timing_(timing), stage_(std::move(stage)), start_(std::chrono::steady_clock::now()) {}
  ~ScopedStage() { stop(); }
  void stop() {
    if (!timing_) return;
    timing_->add(
        stage_, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_)
                    .count());
    timing_ = nullptr;
  }

 private:
  FrameTiming* timing_;
  std::string stage_;
  std::chrono::steady_clock::time_point start_;
};

struct StageSummary {
  std::string stage;
  std::size_t frames = 0;
  double median_ms = 0, p95_ms = 0, max_ms = 0, mean_ms = 0;
};

/// All frames of a run.
class TimingLog {
 public:
  void add(const FrameTiming& frame) { frames_.push_back(frame); }
  const std::vector<FrameTiming>& frames() const { return frames_; }
  /// Stage names in first-seen order.
  std::vector<std::string> stages() const;
  /// One row per stage plus "total"; frames where a stage did not run count as 0 ms.
  std::vector<StageSummary> summary() const;
  /// CSV: t, one column per stage (ms), total.
  std::string toCsv() const;
  /// Markdown table of the summary.
  std::string summaryTable() const;

 private:
  std::vector<FrameTiming> frames_;
};

/// Percentile (0..100) by linear interpolation; 0 for an empty input.
double percentile(std::vector<double> values, double p);

}  // namespace alvio
