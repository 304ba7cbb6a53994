#pragma once
// A directed 2D line segment in pixel coordinates and the small amount of plane geometry the
// line trackers need. LSD orients segments by the gradient (dark side consistently on one
// side), so the direction start -> end is meaningful and kept through tracking.

#include <Eigen/Core>
#include <vector>

namespace alvio {

struct LineSegment {
  Eigen::Vector2d start = Eigen::Vector2d::Zero();
  Eigen::Vector2d end = Eigen::Vector2d::Zero();

  LineSegment() = default;
  LineSegment(const Eigen::Vector2d& s, const Eigen::Vector2d& e) : start(s), end(e) {}

  double length() const { return (end - start).norm(); }
  Eigen::Vector2d midpoint() const { return 0.5 * (start + end); }
  /// Unit direction start -> end.
  Eigen::Vector2d direction() const { return (end - start).normalized(); }
  /// Direction angle atan2(dy, dx) in (-pi, pi].
  double angle() const;
  /// Unsigned distance of p to the infinite line through the segment.
  double distanceToLine(const Eigen::Vector2d& p) const;
  /// Position of p's projection along the segment: 0 at start, length() at end.
  double positionAlong(const Eigen::Vector2d& p) const;
  /// Point at `position` along the segment's line (see positionAlong).
  Eigen::Vector2d pointAt(double position) const { return start + position * direction(); }
};

/// Absolute difference of two directed angles, in [0, pi].
double angleDifference(double a, double b);

/// Length of the overlap of b's projection onto a with a itself (0 if disjoint).
double projectedOverlap(const LineSegment& a, const LineSegment& b);

/// Clip a segment to the rectangle [x_min, x_max] x [y_min, y_max] along its own line.
/// Returns false if nothing is left; `clipped` tells whether an endpoint moved.
bool clipSegmentToRect(LineSegment* segment, double x_min, double y_min, double x_max, double y_max,
                       bool* clipped);

/// One segment standing for collinear pieces: the length-weighted mean direction (the
/// pieces' common orientation is kept) through the length-weighted centroid, spanning the
/// extreme projections of all pieces' endpoints.
LineSegment mergeCollinearSegments(const std::vector<LineSegment>& pieces);

/// Total-least-squares line through points (at least 2), as a segment spanning their
/// projections; `reference` orients it. Returns false if the points do not define a line.
bool fitSegmentToPoints(const std::vector<Eigen::Vector2d>& points,
                        const Eigen::Vector2d& reference, LineSegment* segment);

}  // namespace alvio
