#include "alvio/mapping/occupancy_map.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <utility>

#include "alvio/common/error.h"
#include "alvio/config/yaml_reader.h"
#include "alvio/mapping/segment_geometry.h"

namespace alvio {

OccupancyMapOptions OccupancyMapOptions::load(const YamlReader& yaml, const std::string& prefix) {
  OccupancyMapOptions o;
  const std::string p = prefix + ".";
  o.resolution = yaml.getDouble(p + "resolution", o.resolution);
  o.max_range = yaml.getDouble(p + "sensor_model_max_range", o.max_range);
  o.hit = yaml.getDouble(p + "sensor_model_hit", o.hit);
  o.miss = yaml.getDouble(p + "sensor_model_miss", o.miss);
  o.clamp_min = yaml.getDouble(p + "sensor_model_min", o.clamp_min);
  o.clamp_max = yaml.getDouble(p + "sensor_model_max", o.clamp_max);
  o.line_sample_step_m = yaml.getDouble(p + "line_sample_step_m", o.line_sample_step_m);
  o.carve_free_space = yaml.getBool(p + "carve_free_space", o.carve_free_space);
  o.min_line_observations = yaml.getInt(p + "min_line_observations", o.min_line_observations);
  auto check = [&](bool ok, const std::string& key, const std::string& what) {
    if (!ok) throw Error(yaml.where(p + key) + " " + what);
  };
  check(o.resolution > 0, "resolution", "must be > 0");
  check(o.max_range == -1 || o.max_range > 0, "sensor_model_max_range", "must be > 0 or -1");
  check(o.hit > 0.5 && o.hit < 1, "sensor_model_hit", "must be in (0.5, 1)");
  check(o.miss > 0 && o.miss < 0.5, "sensor_model_miss", "must be in (0, 0.5)");
  check(o.clamp_min > 0 && o.clamp_min < 0.5, "sensor_model_min", "must be in (0, 0.5)");
  check(o.clamp_max > 0.5 && o.clamp_max < 1, "sensor_model_max", "must be in (0.5, 1)");
  check(o.line_sample_step_m >= 0, "line_sample_step_m", "must be >= 0 (0: resolution / 2)");
  return o;
}

OccupancyMap::OccupancyMap(const OccupancyMapOptions& options)
    : options_(options), tree_(std::make_unique<octomap::OcTree>(options.resolution)) {
  tree_->setProbHit(options.hit);
  tree_->setProbMiss(options.miss);
  tree_->setClampingThresMin(options.clamp_min);
  tree_->setClampingThresMax(options.clamp_max);
}

namespace {
constexpr double kMaxRayLength_m = 100.0;

// Index of the highest set bit of v (> 0); the builtin where the compiler has one.
int highestSetBit(uint64_t v) {
#if defined(__GNUC__) || defined(__clang__)
  return 63 - __builtin_clzll(v);
#else
  int i = 0;
  while (v >>= 1) ++i;
  return i;
#endif
}

// Bit i of v moved to bit 3i.
uint64_t spreadBits(uint16_t v) {
  uint64_t x = v;
  x = (x | (x << 16)) & 0x0000FF0000FFULL;
  x = (x | (x << 8)) & 0x00F00F00F00FULL;
  x = (x | (x << 4)) & 0x0C30C30C30C3ULL;
  x = (x | (x << 2)) & 0x249249249249ULL;
  return x;
}

// The key's path from the root: at tree depth d the three bits at 3 (15 - d) are the child
// index OcTree::computeChildIdx gives. Sorted codes visit the leaves depth first.
uint64_t pathCode(const octomap::OcTreeKey& key) {
  return spreadBits(key.k[0]) | (spreadBits(key.k[1]) << 1) | (spreadBits(key.k[2]) << 2);
}

// Sorts by the 48-bit path code, 11 bits a pass from the lowest; a pass is skipped where every
// code has the same digit (the high ones: one insertion's voxels lie near each other). The codes
// are unique, so the order is std::sort's; on a keyframe's 8500 voxels it takes a sixth of the
// time (boost's spreadsort saved 14 %).
template <typename Update>
void sortByCode(std::vector<Update>* updates, std::vector<Update>* scratch) {
  constexpr int kBits = 11;
  constexpr uint64_t kMask = (1u << kBits) - 1;
  if (updates->empty()) return;
  scratch->resize(updates->size());
  std::vector<uint32_t> start(kMask + 1);
  for (int shift = 0; shift < 48; shift += kBits) {
    std::fill(start.begin(), start.end(), 0u);
    for (const Update& u : *updates) ++start[(u.code >> shift) & kMask];
    if (start[(updates->front().code >> shift) & kMask] == updates->size()) continue;
    uint32_t sum = 0;
    for (uint32_t& s : start) sum += std::exchange(s, sum);
    for (const Update& u : *updates) (*scratch)[start[(u.code >> shift) & kMask]++] = u;
    updates->swap(*scratch);
  }
}
}  // namespace

void OccupancyMap::syncInnerNodes() const {
  if (!inner_nodes_stale_) return;
  tree_->updateInnerOccupancy();
  tree_->prune();
  inner_nodes_stale_ = false;
}

const octomap::OcTree& OccupancyMap::tree() const {
  syncInnerNodes();
  return *tree_;
}

void OccupancyMap::insert(const Eigen::Vector3d& origin_w,
                          const std::vector<Eigen::Vector3d>& points_w) {
  if (!origin_w.allFinite()) return;
  const octomap::point3d origin(origin_w.x(), origin_w.y(), origin_w.z());
  if (!options_.carve_free_space) {
    for (const Eigen::Vector3d& p : points_w) {
      if (!p.allFinite()) continue;
      if (options_.max_range > 0 && (p - origin_w).norm() > options_.max_range) continue;
      tree_->updateNode(octomap::point3d(p.x(), p.y(), p.z()), true, /*lazy_eval=*/true);
    }
    inner_nodes_stale_ = true;
    return;
  }
  // As OcTree::insertPointCloud with lazy evaluation and discretisation (one ray per end voxel,
  // to its centre, which matters for densely sampled lines), with the same voxels, but:
  // - the ray keys are gathered in one vector, sorted and merged (a voxel both free and
  //   occupied is occupied, as in OctoMap) instead of going through two hash sets;
  // - each voxel is updated, or its path created, where the descent reaches it: updateNode
  //   searches the tree from the root and then descends it a second time. The voxels are
  //   visited in the tree's depth-first order, each descent starting where the last one's
  //   path parts from it: neighbouring voxels share most of their path.
  // Same map: each voxel's update depends on that voxel alone.
  updates_.clear();
  for (const Eigen::Vector3d& p : points_w) {
    // Even with an unlimited range, a diverged landmark kilometres away would make the ray
    // caster allocate millions of keys: such points are never inserted.
    if (!p.allFinite() || (p - origin_w).norm() >= kMaxRayLength_m) continue;
    const octomap::OcTreeKey key = tree_->coordToKey(octomap::point3d(p.x(), p.y(), p.z()));
    updates_.push_back({pathCode(key), key, true});
  }
  sortByCode(&updates_, &scratch_);
  end_keys_.clear();
  for (std::size_t i = 0; i < updates_.size(); ++i)
    if (i == 0 || updates_[i].code != updates_[i - 1].code) end_keys_.push_back(updates_[i].key);
  updates_.clear();
  auto addRay = [&](const octomap::point3d& end) {
    if (!tree_->computeRayKeys(origin, end, ray_)) return;
    for (const octomap::OcTreeKey& key : ray_) updates_.push_back({pathCode(key), key, false});
  };
  for (const octomap::OcTreeKey& end_key : end_keys_) {
    const octomap::point3d end = tree_->keyToCoord(end_key);
    if (options_.max_range < 0.0 || (end - origin).norm() <= options_.max_range) {
      addRay(end);
      octomap::OcTreeKey key;
      if (tree_->coordToKeyChecked(end, key)) updates_.push_back({pathCode(key), key, true});
    } else {
      addRay(origin + (end - origin).normalized() * static_cast<float>(options_.max_range));
    }
  }
  sortByCode(&updates_, &scratch_);
  std::size_t merged = 0;
  for (std::size_t i = 0; i < updates_.size(); ++i) {
    if (merged > 0 && updates_[merged - 1].code == updates_[i].code)
      updates_[merged - 1].occupied |= updates_[i].occupied;
    else
      updates_[merged++] = updates_[i];
  }
  updates_.resize(merged);
  const int depth = static_cast<int>(tree_->getTreeDepth());
  const bool in_place = !tree_->isChangeDetectionEnabled() && depth == 16;
  // path[d]: the node at depth d on the last key's path, valid for d <= valid.
  octomap::OcTreeNode* path[17];
  int valid = 0;
  uint64_t last_code = 0;
  for (const VoxelUpdate& u : updates_) {
    octomap::OcTreeNode* leaf = nullptr;
    if (in_place && tree_->getRoot()) {
      path[0] = tree_->getRoot();
      // The depths where this key takes the same child as the last one: those above its
      // highest differing 3-bit group.
      const uint64_t differ = u.code ^ last_code;
      const int shared = differ ? 15 - highestSetBit(differ) / 3 : 16;
      int d = std::min(valid, shared);
      octomap::OcTreeNode* node = path[d];
      for (; d < 16; ++d) {
        const unsigned int child = (u.code >> (3 * (15 - d))) & 7u;
        if (!tree_->nodeChildExists(node, child)) break;
        node = tree_->getNodeChild(node, child);
        path[d + 1] = node;
      }
      // A new voxel (about 40 % of them) under a node with other children: its path is
      // created from there, as updateNode would after searching the tree from the root. A
      // node without children above full depth is a pruned leaf, which updateNode expands.
      if (d < 16 && tree_->nodeHasChildren(node)) {
        for (; d < 16; ++d) {
          node = tree_->createNodeChild(node, (u.code >> (3 * (15 - d))) & 7u);
          path[d + 1] = node;
        }
      }
      valid = d;
      if (d == 16) leaf = node;
    }
    last_code = u.code;
    if (leaf) {
      tree_->updateNodeLogOdds(leaf, u.occupied ? tree_->getProbHitLog() : tree_->getProbMissLog());
    } else {
      tree_->updateNode(u.key, u.occupied, /*lazy_eval=*/true);
      valid = 0;  // nodes were created or expanded below the root
    }
  }
  inner_nodes_stale_ = true;
}

void OccupancyMap::insertKeyframe(const KeyframeLandmarks& keyframe) {
  std::vector<Eigen::Vector3d> pts;
  pts.reserve(keyframe.points.size());
  for (const LandmarkPoint& p : keyframe.points) pts.push_back(p.p_w);
  for (const LandmarkSegment& l : keyframe.lines) {
    if (!l.p0_w.allFinite() || !l.p1_w.allFinite()) continue;
    if (l.observations < options_.min_line_observations) continue;
    // A triangulation blow-up would otherwise turn into millions of samples.
    const double step = std::max(options_.lineStep(), (l.p1_w - l.p0_w).norm() / 20000.0);
    for (const Eigen::Vector3d& s : sampleSegment(l.p0_w, l.p1_w, step)) pts.push_back(s);
  }
  insert(keyframe.T_w_c.translation(), pts);
}

std::optional<double> OccupancyMap::occupancy(const Eigen::Vector3d& p_w) const {
  const octomap::OcTreeNode* n = tree().search(p_w.x(), p_w.y(), p_w.z());
  if (!n) return std::nullopt;
  return n->getOccupancy();
}

bool OccupancyMap::isOccupied(const Eigen::Vector3d& p_w) const {
  const octomap::OcTree& t = tree();
  const octomap::OcTreeNode* n = t.search(p_w.x(), p_w.y(), p_w.z());
  return n && t.isNodeOccupied(n);
}

bool OccupancyMap::isFree(const Eigen::Vector3d& p_w) const {
  const octomap::OcTree& t = tree();
  const octomap::OcTreeNode* n = t.search(p_w.x(), p_w.y(), p_w.z());
  return n && !t.isNodeOccupied(n);
}

VoxelCounts countVoxels(const octomap::OcTree& tree) {
  VoxelCounts c;
  const unsigned max_depth = tree.getTreeDepth();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    ++c.leaf_nodes;
    const std::size_t n = std::size_t{1} << (3 * (max_depth - it.getDepth()));
    if (tree.isNodeOccupied(*it)) {
      c.occupied += n;
      const double h = it.getSize() / 2;
      const Eigen::Vector3d centre(it.getX(), it.getY(), it.getZ());
      lo = lo.cwiseMin(centre - Eigen::Vector3d::Constant(h));
      hi = hi.cwiseMax(centre + Eigen::Vector3d::Constant(h));
    } else {
      c.free += n;
    }
  }
  if (c.occupied > 0) {
    c.occupied_min = lo;
    c.occupied_max = hi;
  }
  return c;
}

std::vector<Eigen::Vector3d> occupiedVoxelCentres(const octomap::OcTree& tree) {
  std::vector<Eigen::Vector3d> out;
  const double res = tree.getResolution();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const double size = it.getSize();
    const int n = std::max(1, static_cast<int>(std::lround(size / res)));
    const Eigen::Vector3d corner =
        Eigen::Vector3d(it.getX(), it.getY(), it.getZ()) - Eigen::Vector3d::Constant(size / 2);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k)
          out.push_back(corner + res * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5));
  }
  return out;
}

}  // namespace alvio
