#pragma once
// What the front end hands the estimator for one image: tracked points and lines
// with stable IDs, in pixels and in undistorted normalised coordinates.

#include <Eigen/Core>
#include <Eigen/StdVector>
#include <cstdint>
#include <vector>

namespace alvio {

struct PointObservation {
  int id = -1;
  Eigen::Vector2d px = Eigen::Vector2d::Zero();        ///< distorted pixel position
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();        ///< undistorted normalised (x/z, y/z)
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  ///< of xy, per second
  int track_count = 1;                                 ///< frames this point has been tracked
};

struct LineObservation {
  int id = -1;                                         ///< track ID, kept while the line is tracked
  Eigen::Vector2d start_px = Eigen::Vector2d::Zero();  ///< in the undistorted pinhole image
  Eigen::Vector2d end_px = Eigen::Vector2d::Zero();
  Eigen::Vector2d start_norm = Eigen::Vector2d::Zero();  ///< undistorted normalised
  Eigen::Vector2d end_norm = Eigen::Vector2d::Zero();
  int track_count = 1;  ///< frames this ID has been observed in, this one included
  /// The segment moved onto its edge in the full-resolution image (lines.map_edges): used by
  /// the line map's final fit; the estimator keeps the positions above unless
  /// estimator.line_residuals_on_edges. `edge_checked`: the edge was looked for (found or not).
  bool edge_checked = false;
  bool on_edge = false;
  Eigen::Vector2d edge_start_norm = Eigen::Vector2d::Zero();
  Eigen::Vector2d edge_end_norm = Eigen::Vector2d::Zero();
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

struct LineTrackStats {
  int detected = 0;   ///< LSD segments kept by the detector
  int tracked = 0;    ///< observations continuing a previous ID (types 1, 3 and 4)
  int new_lines = 0;  ///< observations with a new ID (type 2)
  int merged = 0;     ///< tracked lines merged from two or more detections (type 3)
  int clipped = 0;    ///< tracked lines whose prediction was clipped at the border (type 4)
  double undistort_ms = 0.0;
  double detect_ms = 0.0;
  double track_ms = 0.0;  ///< association (optical flow or descriptors, matching)
};

struct FeatureFrame {
  int64_t t_ns = 0;
  std::vector<PointObservation> points;
  std::vector<LineObservation, Eigen::aligned_allocator<LineObservation>> lines;
  LineTrackStats line_stats;
  double mean_intensity = 0;  ///< average pixel value (sensitivity analysis, diagnostics)
  double t() const { return static_cast<double>(t_ns) * 1e-9; }
};

}  // namespace alvio
