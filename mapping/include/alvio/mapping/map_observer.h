#pragma once
// Builds the map during an offline run: a RunObserver that feeds the map builder
// with the estimator's keyframe landmarks (points anchored in the oldest keyframe
// when the window slides) and the lines that retire from the window (refined
// over their whole track), and saves the map files into the run's folder.

#include <memory>
#include <string>

#include "alvio/mapping/estimator_keyframe_feed.h"
#include "alvio/mapping/map_builder.h"
#include "alvio/pipeline/run_observer.h"

namespace alvio {

class MapObserver : public RunObserver {
 public:
  MapObserver(const MappingOptions& options, const Eigen::Isometry3d& T_b_c);

  void onStart(const RunInfo& info) override;
  void onFrame(const FrameView& frame) override;
  void onFinish(const RunResult& result) override;
  std::string stage() const override { return "mapping"; }

  const MapBuilder& map() const { return map_; }
  MapSummary summary() const { return map_.summary(); }
  /// Paths of the files written by onFinish (empty before).
  const MapFilePaths& files() const { return files_; }

 private:
  Eigen::Isometry3d T_b_c_;
  MapBuilder map_;
  EstimatorKeyframeFeed feed_;
  std::string out_dir_;
  const VioPipeline* pipeline_ = nullptr;  // from the first onFrame to onFinish
  MapFilePaths files_;
};

}  // namespace alvio
