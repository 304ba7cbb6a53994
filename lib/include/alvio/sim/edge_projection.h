#pragma once
// True line correspondences for evaluating line trackers: which parts of the
// scene's 3D edges a camera sees (in front, inside the image, not occluded),
// and where they project.

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "alvio/camera/camera_model.h"
#include "alvio/sim/scene.h"

namespace alvio::sim {

struct VisibleEdge {
  int edge_id = 0;
  /// The visible part of the edge (the longest unoccluded run), in the world.
  Eigen::Vector3d a_w = Eigen::Vector3d::Zero(), b_w = Eigen::Vector3d::Zero();
  /// Its end points in the (distorted) image. The projection of a straight edge is
  /// curved by the lens; sample between a_w and b_w for the curve.
  Eigen::Vector2d a_px = Eigen::Vector2d::Zero(), b_px = Eigen::Vector2d::Zero();
  double visible_fraction = 0.0;  ///< of the whole 3D edge
};

struct EdgeProjectionOptions {
  int samples_per_edge = 48;
  double min_length_px = 15.0;  ///< shorter visible parts are dropped
  double border_px = 1.0;
};

/// The scene edges visible from a camera at T_w_c.
std::vector<VisibleEdge> projectVisibleEdges(const Scene& scene, const CameraModel& camera,
                                             const Eigen::Isometry3d& T_w_c,
                                             const EdgeProjectionOptions& options = {});

/// Write the scene's 3D edges as CSV: id, ax, ay, az, bx, by, bz, object name.
void writeSceneEdgesCsv(const std::string& path, const Scene& scene);
/// Read such a CSV back (the object index is -1: the file only names the object). Throws
/// alvio::Error naming the file and line of a malformed row.
std::vector<SceneEdge> readSceneEdgesCsv(const std::string& path);

}  // namespace alvio::sim
