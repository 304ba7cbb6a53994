#include "alvio/lines/line_segment.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

namespace alvio {

double LineSegment::angle() const {
  const Eigen::Vector2d d = end - start;
  return std::atan2(d.y(), d.x());
}

double LineSegment::distanceToLine(const Eigen::Vector2d& p) const {
  const Eigen::Vector2d u = direction();
  const Eigen::Vector2d v = p - start;
  return std::abs(u.x() * v.y() - u.y() * v.x());
}

double LineSegment::positionAlong(const Eigen::Vector2d& p) const {
  return direction().dot(p - start);
}

double angleDifference(double a, double b) {
  constexpr double kPi = 3.14159265358979323846;
  const double d = std::fmod(std::abs(a - b), 2.0 * kPi);
  return d > kPi ? 2.0 * kPi - d : d;
}

double projectedOverlap(const LineSegment& a, const LineSegment& b) {
  const double p0 = a.positionAlong(b.start), p1 = a.positionAlong(b.end);
  const double lo = std::max(0.0, std::min(p0, p1));
  const double hi = std::min(a.length(), std::max(p0, p1));
  return std::max(0.0, hi - lo);
}

bool clipSegmentToRect(LineSegment* segment, double x_min, double y_min, double x_max, double y_max,
                       bool* clipped) {
  // Liang-Barsky: keep the parameter range t in [0, 1] of start + t (end - start) inside.
  const Eigen::Vector2d d = segment->end - segment->start;
  double t0 = 0.0, t1 = 1.0;
  const double p[4] = {-d.x(), d.x(), -d.y(), d.y()};
  const double q[4] = {segment->start.x() - x_min, x_max - segment->start.x(),
                       segment->start.y() - y_min, y_max - segment->start.y()};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0.0) {
      if (q[i] < 0.0) return false;  // parallel to this border and outside it
      continue;
    }
    const double t = q[i] / p[i];
    if (p[i] < 0.0)
      t0 = std::max(t0, t);
    else
      t1 = std::min(t1, t);
  }
  if (t0 >= t1) return false;
  *clipped = t0 > 0.0 || t1 < 1.0;
  const Eigen::Vector2d s = segment->start;
  segment->start = s + t0 * d;
  segment->end = s + t1 * d;
  return true;
}

LineSegment mergeCollinearSegments(const std::vector<LineSegment>& pieces) {
  Eigen::Vector2d dir = Eigen::Vector2d::Zero(), centroid = Eigen::Vector2d::Zero();
  double total = 0.0;
  for (const LineSegment& s : pieces) {
    const double len = s.length();
    dir += s.end - s.start;  // = len * unit direction
    centroid += len * s.midpoint();
    total += len;
  }
  if (total <= 0.0) return pieces.front();
  centroid /= total;
  const Eigen::Vector2d u = dir.normalized();
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const LineSegment& s : pieces) {
    for (const Eigen::Vector2d& p : {s.start, s.end}) {
      const double t = u.dot(p - centroid);
      lo = std::min(lo, t);
      hi = std::max(hi, t);
    }
  }
  return LineSegment(centroid + lo * u, centroid + hi * u);
}

bool fitSegmentToPoints(const std::vector<Eigen::Vector2d>& points,
                        const Eigen::Vector2d& reference, LineSegment* segment) {
  if (points.size() < 2) return false;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const auto& p : points) cov += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
  // The spread along the line must dominate; a point cloud has no direction.
  if (!(eig.eigenvalues()(1) > 1e-6) || eig.eigenvalues()(0) > 0.25 * eig.eigenvalues()(1))
    return false;
  Eigen::Vector2d u = eig.eigenvectors().col(1);
  if (u.dot(reference) < 0.0) u = -u;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& p : points) {
    lo = std::min(lo, u.dot(p - mean));
    hi = std::max(hi, u.dot(p - mean));
  }
  *segment = LineSegment(mean + lo * u, mean + hi * u);
  return true;
}

}  // namespace alvio
