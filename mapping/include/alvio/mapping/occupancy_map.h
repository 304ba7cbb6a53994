#pragma once
// The occupancy map: an octomap::OcTree fed with triangulated points and densely
// sampled line segments as occupied, free space carved by casting rays from the
// keyframe camera centre (octomap's insertPointCloud). The sensor model carries
// octomap_server's parameter names and defaults.

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <octomap/OcTree.h>

#include "alvio/mapping/keyframe_landmarks.h"

namespace alvio {

class YamlReader;

struct OccupancyMapOptions {
  double resolution = 0.05;  ///< voxel edge (m): octomap_server `resolution`
  /// Rays are cut at this range (m), -1 = unlimited: `sensor_model/max_range`. Beyond it a
  /// landmark only carves free space up to the range and is not marked occupied.
  double max_range = -1;
  double hit = 0.7;               ///< `sensor_model/hit`
  double miss = 0.4;              ///< `sensor_model/miss`
  double clamp_min = 0.12;        ///< `sensor_model/min`
  double clamp_max = 0.97;        ///< `sensor_model/max`
  double line_sample_step_m = 0;  ///< spacing of samples along lines; 0 = resolution / 2
  bool carve_free_space = true;   ///< false: mark endpoints only, no ray casting
  /// Lines reported with fewer image observations do not go into the tree (a one-off
  /// outlier segment would mark a whole row of voxels).
  int min_line_observations = 3;

  /// Read the keys under `prefix` ("mapping.octomap"): resolution, sensor_model_max_range,
  /// sensor_model_hit, sensor_model_miss, sensor_model_min, sensor_model_max,
  /// line_sample_step_m, carve_free_space, min_line_observations. Throws alvio::Error naming the
  /// key.
  static OccupancyMapOptions load(const YamlReader& yaml, const std::string& prefix);
  double lineStep() const { return line_sample_step_m > 0 ? line_sample_step_m : resolution / 2; }
};

/// Voxel statistics of a tree, in voxels of the finest resolution (a pruned leaf at a
/// coarser depth counts as all the voxels it covers).
struct VoxelCounts {
  std::size_t occupied = 0, free = 0;
  std::size_t leaf_nodes = 0;
  /// Bounding box of the occupied voxels (corners); empty() when there are none.
  Eigen::Vector3d occupied_min = Eigen::Vector3d::Zero(), occupied_max = Eigen::Vector3d::Zero();
  bool empty() const { return occupied == 0; }
};
VoxelCounts countVoxels(const octomap::OcTree& tree);

/// Centres of the occupied voxels at the finest resolution.
std::vector<Eigen::Vector3d> occupiedVoxelCentres(const octomap::OcTree& tree);

class OccupancyMap {
 public:
  explicit OccupancyMap(const OccupancyMapOptions& options = OccupancyMapOptions());

  /// Mark `points_w` occupied and, when carving, the voxels on the rays from `origin_w`
  /// to them free.
  void insert(const Eigen::Vector3d& origin_w, const std::vector<Eigen::Vector3d>& points_w);
  /// Insert a keyframe: its points and its lines (those with at least min_line_observations)
  /// sampled every lineStep(), seen from the keyframe's camera centre.
  void insertKeyframe(const KeyframeLandmarks& keyframe);

  /// Occupancy probability of the voxel at `p_w`, or nullopt when unknown.
  std::optional<double> occupancy(const Eigen::Vector3d& p_w) const;
  bool isOccupied(const Eigen::Vector3d& p_w) const;
  bool isFree(const Eigen::Vector3d& p_w) const;

  /// The tree with its inner nodes up to date and pruned.
  const octomap::OcTree& tree() const;
  VoxelCounts counts() const { return countVoxels(tree()); }
  std::size_t memoryBytes() const { return tree().memoryUsage(); }
  const OccupancyMapOptions& options() const { return options_; }

 private:
  /// Insertions update the voxels only (OctoMap's lazy evaluation): walking back up the
  /// tree after every voxel costs more than updating the inner nodes and pruning once,
  /// when the tree is read. Periodic pruning was measured: each pass over the whole tree
  /// costs more than it saves, and the unpruned tree is only ~1 % larger.
  void syncInnerNodes() const;

  struct VoxelUpdate {
    uint64_t code;  ///< the key's path from the root, three bits per depth
    octomap::OcTreeKey key;
    bool occupied;
  };

  OccupancyMapOptions options_;
  std::unique_ptr<octomap::OcTree> tree_;
  mutable bool inner_nodes_stale_ = false;
  // One insertion's work, kept for its capacity (a KeyRay allocates room for 100000 keys).
  std::vector<VoxelUpdate> updates_, scratch_;
  std::vector<octomap::OcTreeKey> end_keys_;
  octomap::KeyRay ray_;
};

}  // namespace alvio
