#include "alvio/mapping/map_evaluation.h"

#include <algorithm>
#include <cmath>

#include "alvio/mapping/occupancy_map.h"

namespace alvio {

namespace {

// Length of `s` lying within the tolerances of one of `others` (sampled).
double matchedLength(const Segment3& s, const std::vector<Segment3>& others, double dist_tol,
                     double angle_tol) {
  const double len = s.length();
  if (!(len > 0)) return 0;
  const Eigen::Vector3d u = s.direction();
  // Candidates: direction compatible and bounding boxes within the tolerance.
  const Eigen::Vector3d lo = s.p0.cwiseMin(s.p1).array() - dist_tol;
  const Eigen::Vector3d hi = s.p0.cwiseMax(s.p1).array() + dist_tol;
  std::vector<const Segment3*> candidates;
  for (const Segment3& o : others) {
    if (!(o.length() > 0) || lineAngle(u, o.direction()) > angle_tol) continue;
    const Eigen::Vector3d olo = o.p0.cwiseMin(o.p1), ohi = o.p0.cwiseMax(o.p1);
    if ((olo.array() > hi.array()).any() || (ohi.array() < lo.array()).any()) continue;
    candidates.push_back(&o);
  }
  if (candidates.empty()) return 0;
  // Midpoint rule over n equal pieces.
  const double step = std::max(1e-3, dist_tol / 2);
  const int n = std::max(1, static_cast<int>(std::ceil(len / step)));
  int hits = 0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p = s.p0 + (s.p1 - s.p0) * ((i + 0.5) / n);
    for (const Segment3* o : candidates)
      if (pointSegmentDistance(p, o->p0, o->p1) <= dist_tol) {
        ++hits;
        break;
      }
  }
  return len * hits / n;
}

}  // namespace

LineMapEvaluation evaluateLineMap(const std::vector<Segment3>& map_lines,
                                  const std::vector<Segment3>& true_edges, double dist_tol_m,
                                  double angle_tol_rad) {
  LineMapEvaluation e;
  e.map_lines = map_lines.size();
  e.true_edges = true_edges.size();
  for (const Segment3& s : map_lines) {
    e.map_length_m += s.length();
    e.matched_map_length_m += matchedLength(s, true_edges, dist_tol_m, angle_tol_rad);
  }
  for (const Segment3& t : true_edges) {
    e.true_length_m += t.length();
    e.covered_true_length_m += matchedLength(t, map_lines, dist_tol_m, angle_tol_rad);
  }
  e.precision = e.map_length_m > 0 ? e.matched_map_length_m / e.map_length_m : 0;
  e.recall = e.true_length_m > 0 ? e.covered_true_length_m / e.true_length_m : 0;
  return e;
}

OccupancyEvaluation evaluateOccupancy(const octomap::OcTree& tree,
                                      const SurfaceDistanceFn& surface_distance,
                                      double tolerance_m) {
  OccupancyEvaluation e;
  double sum = 0;
  for (const Eigen::Vector3d& c : occupiedVoxelCentres(tree)) {
    const double d = surface_distance(c);
    ++e.occupied_voxels;
    sum += d;
    if (d <= tolerance_m) ++e.within_tolerance;
  }
  if (e.occupied_voxels > 0) {
    e.fraction = static_cast<double>(e.within_tolerance) / e.occupied_voxels;
    e.mean_distance_m = sum / e.occupied_voxels;
  }
  return e;
}

}  // namespace alvio
