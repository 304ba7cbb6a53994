#include "alvio/eval/line_truth_association.h"
#include "alvio/common/angles.h"

#include <algorithm>
#include <cmath>

namespace alvio {

EdgeAssociation associateWithEdge(const LineSegment& segment, const ProjectedEdges& edges,
                                  const EdgeAssociationOptions& options) {
  EdgeAssociation out;
  const double length = segment.length();
  if (!(length > 0)) return out;
  const double max_angle = options.max_angle_deg * kDegToRad;
  double best = 0;
  for (const ProjectedEdge& e : edges) {
    const LineSegment edge(e.a, e.b);
    if (!(edge.length() > 0)) continue;
    const double d_start = edge.distanceToLine(segment.start);
    const double d_end = edge.distanceToLine(segment.end);
    const double d = std::max(d_start, d_end);
    if (d > options.max_endpoint_distance_px) continue;
    // Undirected: an edge has no preferred orientation, LSD's comes from the gradient.
    const double diff = angleDifference(segment.angle(), edge.angle());
    const double angle = std::min(diff, M_PI - diff);
    if (angle > max_angle) continue;
    if (projectedOverlap(edge, segment) < options.min_overlap_ratio * length) continue;
    out.compatible.push_back(e.edge_id);
    if (out.edge_id < 0 || d < best) {
      best = d;
      out.edge_id = e.edge_id;
      out.endpoint_distance_px = d;
      out.start_distance_px = d_start;
      out.end_distance_px = d_end;
      out.angle_deg = angle * kRadToDeg;
    }
  }
  return out;
}

}  // namespace alvio
