#pragma once
// Triangulation of a 3D line from segment observations with known camera poses:
// two-view plane intersection, best-pair selection, multi-view refinement, and the
// segment extent (endpoints) for maps.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "alvio/geometry/plucker_line.h"

namespace alvio {

class YamlReader;

/// One observation of a line: the camera pose and the segment's endpoints in undistorted
/// normalised coordinates.
struct LineView {
  Eigen::Isometry3d T_w_c = Eigen::Isometry3d::Identity();
  Eigen::Vector2d start_norm = Eigen::Vector2d::Zero();
  Eigen::Vector2d end_norm = Eigen::Vector2d::Zero();
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};
using LineViews = std::vector<LineView, Eigen::aligned_allocator<LineView>>;

struct LineTriangulationOptions {
  /// Minimum angle between the two back-projected planes [deg]; below, the planes are
  /// (nearly) the same plane and their intersection is noise.
  double min_plane_angle_deg = 1.0;
  /// Minimum angle between the baseline and each back-projected plane [deg]: a plane
  /// containing the baseline means the observed line passes through the epipole.
  double min_epipole_angle_deg = 1.0;
  /// Minimum baseline [m].
  double min_baseline = 1e-3;
  /// The line must lie at least this far in front of the cameras [m] where it is seen.
  double min_depth = 0.05;
  /// Refinement: Ceres iterations and the Huber scale in normalised units (0: no loss).
  int refine_max_iterations = 10;
  double refine_huber_scale = 0.0;
  /// Extent: an observed endpoint whose ray meets the line at less than this angle [deg] is
  /// not used, because its position along the line is ill-conditioned (error / sin(angle)).
  double extent_min_ray_angle_deg = 10.0;
  /// Extent: this fraction of the views reaching furthest out at each end is left out
  /// (0: the union of all observed parts).
  double extent_trim_fraction = 0.1;

  static LineTriangulationOptions load(const YamlReader& yaml, const std::string& prefix);
  void validate(const std::string& where) const;
};

enum class LineTriangulationStatus {
  kOk,
  kTooFewViews,
  kBaselineTooSmall,
  kNearEpipole,
  kPlanesNearlyParallel,
  kBehindCamera,
  kRefinementFailed,
};
const char* toString(LineTriangulationStatus status);

/// Two-view triangulation: intersect the planes through each camera centre and its observed
/// segment, pi = [s x e; 0] in its camera frame. With both planes in the world frame,
/// pi_i = [a_i; b_i], the dual Plucker matrix L* = pi_1 pi_2^T - pi_2 pi_1^T holds the line
/// L = (n, d) = (b_1 a_2 - b_2 a_1, a_1 x a_2). On success writes the world-frame line.
LineTriangulationStatus triangulateLine(const LineView& a, const LineView& b,
                                        const LineTriangulationOptions& options,
                                        PluckerLine* line_w);

/// Triangulate from the pair with the largest plane angle (the best-conditioned pair),
/// then refine over all views. The views' order does not matter.
LineTriangulationStatus triangulateLineMultiView(const LineViews& views,
                                                 const LineTriangulationOptions& options,
                                                 PluckerLine* line_w);

/// Minimise the endpoint-to-line distances (LineProjectionFactor, normalised units) over
/// all views with the poses fixed. Returns false (and leaves `line_w`) if Ceres fails.
bool refineLine(const LineViews& views, const LineTriangulationOptions& options,
                PluckerLine* line_w);

/// Ray parameter and line parameter of the closest points of a ray (origin o, direction r)
/// and a line; false if they are (nearly) parallel. The line point is p0 + s d / |d| with
/// p0 the line's point closest to the origin.
bool closestPointOnLineToRay(const PluckerLine& line, const Eigen::Vector3d& o,
                             const Eigen::Vector3d& r, double* s_line, double* t_ray);

/// The segment's extent: every observed endpoint's back-projected ray is brought to its
/// closest point on the line; the union of the views' parts along the line gives the
/// endpoints (ordered along d), less the `options.extent_trim_fraction` of views reaching
/// furthest at each end. Endpoints whose ray meets the line at less than
/// `options.extent_min_ray_angle_deg` are skipped. False if no endpoint could be placed in
/// front of its camera.
bool lineExtent(const PluckerLine& line_w, const LineViews& views, Eigen::Vector3d* start_w,
                Eigen::Vector3d* end_w, const LineTriangulationOptions& options = {});

}  // namespace alvio
