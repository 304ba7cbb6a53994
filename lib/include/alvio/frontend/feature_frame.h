#pragma once
// What the front end hands the estimator for one image: tracked features with
// stable IDs, in pixels and in undistorted normalised coordinates.

#include <Eigen/Core>
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

struct FeatureFrame {
  int64_t t_ns = 0;
  std::vector<PointObservation> points;
  double mean_intensity = 0;  ///< average pixel value (sensitivity analysis, diagnostics)
  double t() const { return static_cast<double>(t_ns) * 1e-9; }
};

}  // namespace alvio
