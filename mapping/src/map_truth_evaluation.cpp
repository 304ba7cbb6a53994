#include "alvio/mapping/map_truth_evaluation.h"
#include "alvio/common/angles.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace alvio {

namespace {
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(q * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}
}  // namespace

LineError lineErrorToNearestEdge(const Segment3& line, const std::vector<Segment3>& true_edges) {
  LineError out;
  const Eigen::Vector3d mid = 0.5 * (line.p0 + line.p1);
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < true_edges.size(); ++i) {
    const Segment3& e = true_edges[i];
    const double d =
        (pointSegmentDistance(line.p0, e.p0, e.p1) + pointSegmentDistance(line.p1, e.p0, e.p1) +
         pointSegmentDistance(mid, e.p0, e.p1)) /
        3;
    if (d < best) {
      best = d;
      out.edge = static_cast<int>(i);
    }
  }
  if (out.edge < 0) return out;
  const Segment3& e = true_edges[out.edge];
  out.angle_deg = lineAngle(line.direction(), e.direction()) * kRadToDeg;
  out.midpoint_distance_m = pointLineDistance(mid, e.p0, e.direction());
  return out;
}

double lineSurfaceDistance(const Segment3& line, const SurfaceDistanceFn& surface_distance) {
  return std::max({surface_distance(line.p0), surface_distance(line.p1),
                   surface_distance(0.5 * (line.p0 + line.p1))});
}

LineErrorSummary summariseLineErrors(const std::vector<Segment3>& lines,
                                     const std::vector<Segment3>& true_edges) {
  LineErrorSummary s;
  std::vector<double> angles, distances;
  for (const Segment3& l : lines) {
    const LineError e = lineErrorToNearestEdge(l, true_edges);
    if (e.edge < 0) continue;
    angles.push_back(e.angle_deg);
    distances.push_back(e.midpoint_distance_m);
  }
  s.lines = angles.size();
  s.median_angle_deg = quantile(angles, 0.5);
  s.p90_angle_deg = quantile(angles, 0.9);
  s.median_midpoint_distance_m = quantile(distances, 0.5);
  s.p90_midpoint_distance_m = quantile(distances, 0.9);
  return s;
}

MapTruthEvaluation evaluateMapAgainstTruth(const std::vector<Segment3>& lines_est,
                                           const octomap::OcTree* tree, const Similarity3& T_gt_est,
                                           const std::vector<Segment3>& true_edges,
                                           const SurfaceDistanceFn& surface_distance,
                                           const MapTruthOptions& options) {
  std::vector<Segment3> lines;
  lines.reserve(lines_est.size());
  for (const Segment3& l : lines_est) lines.push_back({T_gt_est.apply(l.p0), T_gt_est.apply(l.p1)});
  MapTruthEvaluation out;
  out.line_errors = summariseLineErrors(lines, true_edges);
  out.line_map = evaluateLineMap(lines, true_edges, options.line_distance_tol_m,
                                 options.line_angle_tol_deg * kDegToRad);
  double total = 0, on_surface = 0;
  for (const Segment3& l : lines) {
    total += l.length();
    if (lineSurfaceDistance(l, surface_distance) <= options.line_distance_tol_m)
      on_surface += l.length();
  }
  out.line_on_surface_fraction = total > 0 ? on_surface / total : 0;
  if (tree)
    out.occupancy = evaluateOccupancy(
        *tree, [&](const Eigen::Vector3d& c) { return surface_distance(T_gt_est.apply(c)); },
        options.voxel_tolerance_m);
  return out;
}

}  // namespace alvio
