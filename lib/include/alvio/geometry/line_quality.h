#pragma once
// How well a triangulated line is supported by its views: how consistently the observed
// segments fit one 3D line, and how much the cameras moved across it. A track that slid onto
// a neighbouring edge leaves a large residual; a line seen only while the camera moved along
// it (or from far away) is placed by noise. Used to keep such lines out of the maps.

#include <Eigen/Core>
#include <limits>

#include "alvio/geometry/line_triangulation.h"
#include "alvio/geometry/plucker_line.h"

namespace alvio {

/// Distances of observed endpoints (normalised image coordinates) to the image of `line_c`,
/// a line in that camera's frame. False when it projects to a point (seen end-on).
bool imageLineEndpointDistances(const PluckerLine& line_c, const Eigen::Vector2d& start_norm,
                                const Eigen::Vector2d& end_norm, double* start, double* end);
/// The same for a world line and a view.
bool lineEndpointDistances(const PluckerLine& line_w, const LineView& view, double* start,
                           double* end);

/// Root mean square of every view's endpoint distances (normalised units); infinity when the
/// line projects to a point in some view, 0 without views.
double lineReprojectionRms(const PluckerLine& line_w, const LineViews& views);

/// Parallax of the segment start_w..end_w in its views: the spread of the camera centres along
/// the one direction that changes how the line looks (perpendicular to the line and to the mean
/// viewing ray of its midpoint), divided by the median camera-to-midpoint distance. A
/// dimensionless baseline-over-depth; motion along the line or the ray adds nothing.
double lineCrossParallax(const Eigen::Vector3d& start_w, const Eigen::Vector3d& end_w,
                         const LineViews& views);

/// 1-sigma uncertainty of a line fitted to its views, from the information of the views'
/// endpoint-distance residuals at noise `sigma` (normalised units), the poses taken as exact.
struct LineUncertainty {
  double direction_std_deg = 180;  ///< of the direction
  /// Of the point of the line nearest `midpoint_w`, across the line [m]. Grows with depth and
  /// with too little motion across the line, the two things that put a map line off its edge.
  double midpoint_std_m = std::numeric_limits<double>::infinity();
};
LineUncertainty lineUncertainty(const PluckerLine& line_w, const Eigen::Vector3d& midpoint_w,
                                const LineViews& views, double sigma);
/// Only the direction's part (for the window's lines, every frame).
double lineDirectionStdDeg(const PluckerLine& line_w, const LineViews& views, double sigma);

}  // namespace alvio
