#include "alvio/lines/line_tracker.h"

#include <chrono>

#include "alvio/common/error.h"
#include "alvio/lines/descriptor_line_tracker.h"
#include "alvio/lines/edge_refinement.h"
#include "alvio/lines/optical_flow_line_tracker.h"

namespace alvio {
namespace {
double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}
}  // namespace

LineTracker::LineTracker(const CameraOptions& camera, const LineTrackerOptions& options)
    : options_(options),
      undistorter_(camera),
      detector_(options.detector, cv::Size(camera.width, camera.height)) {
  options_.validate("lines");
}

LineFrame LineTracker::track(const cv::Mat& gray, double t,
                             const std::optional<Eigen::Matrix3d>& R_cur_prev) {
  const auto start = std::chrono::steady_clock::now();
  const cv::Mat undistorted = undistorter_.undistort(gray);
  const double undistort_ms = msSince(start);
  LineFrame frame = trackUndistorted(undistorted, t, R_cur_prev);
  frame.stats.undistort_ms = undistort_ms;
  return frame;
}

LineFrame LineTracker::trackUndistorted(const cv::Mat& undistorted, double t,
                                        const std::optional<Eigen::Matrix3d>& R_cur_prev) {
  if (undistorted.type() != CV_8UC1 || undistorted.size() != undistorter_.size())
    throw Error(std::string(name()) + ": expected an 8-bit grey image of the camera's size");
  LineFrame frame;
  frame.t = t;
  auto start = std::chrono::steady_clock::now();
  const bool detect = detectsThisFrame();
  const std::vector<LineSegment> detections =
      detect ? detector_.detect(undistorted, undistorter_.validMask()) : std::vector<LineSegment>();
  frame.stats.detect_ms = msSince(start);
  for (const LineSegment& s : detections)
    frame.stats.detected += s.length() >= detector_.minLength();

  start = std::chrono::steady_clock::now();
  R_cur_prev_ = R_cur_prev;
  associate(undistorted, detections, detect, &frame);
  for (LineObservation& obs : frame.lines) {
    obs.start_norm = undistorter_.pixelToNormalised(obs.start_px);
    obs.end_norm = undistorter_.pixelToNormalised(obs.end_px);
    LineSegment edge(obs.start_px, obs.end_px);
    obs.edge_checked = options_.map_edges;
    if (options_.map_edges && refineSegmentToEdge(undistorted, EdgeRefinementOptions(), &edge)) {
      obs.on_edge = true;
      obs.edge_start_norm = undistorter_.pixelToNormalised(edge.start);
      obs.edge_end_norm = undistorter_.pixelToNormalised(edge.end);
    }
  }
  frame.stats.track_ms = msSince(start);
  return frame;
}

std::vector<int> LineTracker::selectNewLines(const std::vector<LineSegment>& detections,
                                             const std::vector<bool>& used, int tracked) const {
  std::vector<int> selected;
  const int room = options_.detector.max_lines - tracked;
  for (std::size_t j = 0; j < detections.size() && static_cast<int>(selected.size()) < room; ++j)
    if (!used[j] && detections[j].length() >= detector_.minLength())
      selected.push_back(static_cast<int>(j));  // detections come longest first
  return selected;
}

std::unique_ptr<LineTracker> createLineTracker(const CameraOptions& camera,
                                               const LineTrackerOptions& options) {
  if (options.tracker == "flow") return std::make_unique<OpticalFlowLineTracker>(camera, options);
  if (options.tracker == "descriptor")
    return std::make_unique<DescriptorLineTracker>(camera, options);
  throw Error("lines.tracker: unsupported '" + options.tracker + "' (expected flow or descriptor)");
}

}  // namespace alvio
