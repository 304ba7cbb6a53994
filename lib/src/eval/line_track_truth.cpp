#include "alvio/eval/line_track_truth.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

namespace alvio {

namespace {
double median(std::vector<double> v) {
  if (v.empty()) return 0;
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  return v[mid];
}

constexpr std::size_t kBins = std::size(LineTrackTruth::kEndpointBinEdgesPx);

std::size_t lengthBin(double length_px) {
  std::size_t bin = 0;
  while (bin + 1 < kBins && length_px >= LineTrackTruth::kEndpointBinEdgesPx[bin + 1]) ++bin;
  return bin;
}
}  // namespace

void LineTrackTruth::addFrame(const LineFrame& frame, const ProjectedEdges& truth) {
  for (const LineObservation& o : frame.lines) {
    const EdgeAssociation a = associateWithEdge(LineSegment(o.start_px, o.end_px), truth, options_);
    tracks_[o.id].push_back({a.edge_id, a.compatible});
    if (a.edge_id < 0) continue;
    endpoint_px_.push_back(a.endpoint_distance_px);
    if (endpoint_by_length_px_.empty()) endpoint_by_length_px_.resize(kBins);
    std::vector<double>& bin = endpoint_by_length_px_[lengthBin((o.end_px - o.start_px).norm())];
    bin.push_back(a.start_distance_px);
    bin.push_back(a.end_distance_px);
  }
  // The first frame has nothing to associate with: its time is not a tracking time.
  if (frames_ > 0)
    frame_ms_.push_back(frame.stats.undistort_ms + frame.stats.detect_ms + frame.stats.track_ms);
  merged_ += frame.stats.merged;
  clipped_ += frame.stats.clipped;
  ++frames_;
}

LineTrackTruthSummary LineTrackTruth::summarise() const {
  LineTrackTruthSummary s;
  s.frames = frames_;
  s.tracks = tracks_.size();
  s.type3_merged = merged_;
  s.type4_clipped = clipped_;
  std::vector<double> lengths;
  std::size_t judged = 0, correct = 0, strict = 0, single_edge = 0;
  for (const auto& [id, observations] : tracks_) {
    lengths.push_back(static_cast<double>(observations.size()));
    s.observations += observations.size();
    std::map<int, int> votes;
    for (const Observation& o : observations)
      if (o.edge >= 0) ++votes[o.edge];
    int associated = 0;
    for (const auto& [edge, n] : votes) associated += n;
    s.associated_observations += associated;
    if (associated < 2) continue;
    // Ties go to the smallest edge ID (std::map order), so the result is deterministic.
    const int majority =
        std::max_element(votes.begin(), votes.end(), [](const auto& a, const auto& b) {
          return a.second < b.second;
        })->first;
    ++s.evaluated_tracks;
    bool all_correct = true;
    for (const Observation& o : observations) {
      if (o.edge < 0) continue;
      ++judged;
      strict += o.edge == majority;
      const bool ok =
          std::find(o.compatible.begin(), o.compatible.end(), majority) != o.compatible.end();
      correct += ok;
      all_correct = all_correct && ok;
    }
    single_edge += all_correct;
  }
  if (frames_ > 0) s.lines_per_frame = static_cast<double>(s.observations) / frames_;
  if (s.observations > 0)
    s.associated_fraction = static_cast<double>(s.associated_observations) / s.observations;
  if (!lengths.empty()) {
    for (double l : lengths) s.mean_track_length_frames += l / lengths.size();
    s.median_track_length_frames = median(lengths);
  }
  if (judged > 0) {
    s.correct_fraction = static_cast<double>(correct) / judged;
    s.strict_correct_fraction = static_cast<double>(strict) / judged;
  }
  if (s.evaluated_tracks > 0)
    s.single_edge_track_fraction = static_cast<double>(single_edge) / s.evaluated_tracks;
  s.median_endpoint_distance_px = median(endpoint_px_);
  for (std::size_t b = 0; b < endpoint_by_length_px_.size(); ++b) {
    const std::vector<double>& d = endpoint_by_length_px_[b];
    EndpointErrorBin bin;
    bin.min_length_px = kEndpointBinEdgesPx[b];
    bin.max_length_px =
        b + 1 < kBins ? kEndpointBinEdgesPx[b + 1] : std::numeric_limits<double>::infinity();
    bin.endpoints = d.size();
    double squares = 0;
    for (double x : d) squares += x * x;
    if (!d.empty()) bin.rms_px = std::sqrt(squares / d.size());
    bin.median_px = median(d);
    s.endpoint_error_by_length.push_back(bin);
  }
  for (double ms : frame_ms_) s.mean_ms += ms / frame_ms_.size();
  s.median_ms = median(frame_ms_);
  return s;
}

}  // namespace alvio
