#pragma once
// Scores one line tracker's output over a sequence against the true scene edges: every
// observation is associated with the edge it lies on (line_truth_association.h); a track is
// then expected to stay on one edge. A track's edge is the one most of its associated
// observations lie on (the majority); an associated observation is correct when that edge is
// among the edges compatible with it. Observations on no edge (texture lines, occluded or
// clipped truth) are counted but neither correct nor wrong.

#include <cstddef>
#include <map>
#include <vector>

#include "alvio/eval/line_truth_association.h"
#include "alvio/lines/line_tracker.h"

namespace alvio {

/// Endpoint-to-true-line distances of the associated segments whose length falls in
/// [min_length_px, max_length_px): how a segment's position error depends on its length.
struct EndpointErrorBin {
  double min_length_px = 0, max_length_px = 0;
  std::size_t endpoints = 0;
  double rms_px = 0, median_px = 0;
};

struct LineTrackTruthSummary {
  std::size_t frames = 0, observations = 0, associated_observations = 0;
  double lines_per_frame = 0;
  double associated_fraction = 0;  ///< associated / all observations
  std::size_t tracks = 0;          ///< distinct IDs
  double mean_track_length_frames = 0, median_track_length_frames = 0;
  /// Tracks with at least two associated observations: those that can switch edges.
  std::size_t evaluated_tracks = 0;
  /// Associated observations of the evaluated tracks on their track's edge (see above).
  double correct_fraction = 0;
  /// The same, counting an observation correct only when its closest edge is the track's.
  double strict_correct_fraction = 0;
  /// Evaluated tracks whose associated observations are all correct.
  double single_edge_track_fraction = 0;
  double median_endpoint_distance_px = 0;  ///< of the associations (truth consistency)
  /// Each endpoint's distance to its edge's line, by segment length (kEndpointBinEdgesPx).
  /// The association's limit (max_endpoint_distance_px) truncates the distribution.
  std::vector<EndpointErrorBin> endpoint_error_by_length;
  std::size_t type3_merged = 0, type4_clipped = 0;
  /// Front-end time per frame (undistort + detect + associate), from the second frame on.
  double mean_ms = 0, median_ms = 0;
};

class LineTrackTruth {
 public:
  /// Bin edges of endpoint_error_by_length; the last bin is open.
  static constexpr double kEndpointBinEdgesPx[] = {0, 60, 90, 135, 200, 300};

  explicit LineTrackTruth(const EdgeAssociationOptions& options = {}) : options_(options) {}

  /// Account one frame of the tracker and the true edges visible in it.
  void addFrame(const LineFrame& frame, const ProjectedEdges& truth);
  LineTrackTruthSummary summarise() const;

 private:
  struct Observation {
    int edge = -1;
    std::vector<int> compatible;
  };
  EdgeAssociationOptions options_;
  std::map<int, std::vector<Observation>> tracks_;  // ID -> observations in frame order
  std::vector<double> frame_ms_, endpoint_px_;
  std::vector<std::vector<double>> endpoint_by_length_px_;  // per bin, every endpoint
  std::size_t frames_ = 0, merged_ = 0, clipped_ = 0;
};

}  // namespace alvio
