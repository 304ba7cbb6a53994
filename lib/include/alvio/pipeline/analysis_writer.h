#pragma once
// Writes the sensitivity-analysis records of a run (alvio run --analysis DIR):
//   points.csv   window_t, id, x_px, y_px, tracked_frames   (features of each window's first frame)
//   lines.csv    same columns; x, y is the segment midpoint in the undistorted image
//   windows.csv  window_t, frames, mean_intensity, motion_m, points, lines,
//                mean_point_track, mean_line_track
//   image_size.yaml  width, height of the images the positions refer to
// `alvio analyze DIR` fits and plots them.

#include <fstream>
#include <string>

#include "alvio/pipeline/run_observer.h"

namespace alvio {

class AnalysisWriter : public RunObserver {
 public:
  /// Creates `dir`, writes image_size.yaml and opens the three CSV files; throws
  /// alvio::Error naming the path.
  AnalysisWriter(const std::string& dir, int image_width, int image_height);
  void onFrame(const FrameView& frame) override;
  std::string stage() const override { return "analysis"; }
  void onFinish(const RunResult& result) override;
  std::size_t windows() const { return windows_; }

 private:
  std::string dir_;
  std::ofstream points_, lines_, windows_csv_;
  std::size_t windows_ = 0;
};

}  // namespace alvio
