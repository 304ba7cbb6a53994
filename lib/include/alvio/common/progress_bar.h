#pragma once
// Progress output for long offline runs. On a terminal it redraws one line;
// elsewhere (CI logs, pipes) it prints a line every few percent so that logs
// stay short but show the run is alive.

#include <chrono>
#include <cstddef>
#include <string>

namespace alvio {

class ProgressBar {
 public:
  ProgressBar(std::string label, std::size_t total, bool enabled = true);
  ~ProgressBar();
  /// Report that `done` of `total` items are finished; `extra` is appended (e.g. "ATE 0.12").
  void update(std::size_t done, const std::string& extra = "");
  void finish(const std::string& extra = "");

 private:
  std::string label_;
  std::size_t total_;
  bool enabled_;
  bool tty_;
  bool finished_ = false;
  int last_percent_ = -1;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace alvio
