#include "alvio/geometry/line_landmark.h"

#include <algorithm>

namespace alvio {

const char* toString(LineLandmarkStatus status) {
  switch (status) {
    case LineLandmarkStatus::kNew:
      return "new";
    case LineLandmarkStatus::kTriangulated:
      return "triangulated";
    case LineLandmarkStatus::kOptimised:
      return "optimised";
    case LineLandmarkStatus::kOutlier:
      return "outlier";
  }
  return "unknown";
}

Eigen::Vector3d projectOntoLine(const PluckerLine& line, const Eigen::Vector3d& p) {
  const Eigen::Vector3d u = line.d.normalized();
  const Eigen::Vector3d p0 = line.closestPointToOrigin();
  return p0 + u.dot(p - p0) * u;
}

void LineLandmark::setLine(const PluckerLine& line, LineLandmarkStatus new_status) {
  line_w = line;
  status = new_status;
  if (has_extent) {
    start_w = projectOntoLine(line_w, start_w);
    end_w = projectOntoLine(line_w, end_w);
  }
}

void LineLandmark::unionExtent(const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  // Work with positions along the line's unit direction; the ends keep d's orientation.
  const Eigen::Vector3d u = line_w.d.normalized();
  const Eigen::Vector3d p0 = line_w.closestPointToOrigin();
  double lo = std::min(u.dot(p - p0), u.dot(q - p0));
  double hi = std::max(u.dot(p - p0), u.dot(q - p0));
  if (has_extent) {
    lo = std::min({lo, u.dot(start_w - p0), u.dot(end_w - p0)});
    hi = std::max({hi, u.dot(start_w - p0), u.dot(end_w - p0)});
  }
  start_w = p0 + lo * u;
  end_w = p0 + hi * u;
  has_extent = true;
}

}  // namespace alvio
