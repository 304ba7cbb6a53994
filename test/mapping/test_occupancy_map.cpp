// OccupancyMap: sampled segments become occupied voxels, rays carve free space,
// the sensor model and range parameters are applied.
#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <random>
#include <sstream>

#include "alvio/common/error.h"
#include "alvio/config/yaml_reader.h"
#include "alvio/mapping/occupancy_map.h"

using namespace alvio;
using Eigen::Vector3d;

namespace {
KeyframeLandmarks keyframeAtOrigin() {
  KeyframeLandmarks kf;
  kf.T_w_c = Eigen::Isometry3d::Identity();
  return kf;
}

// Gives a plain octomap tree, to compare against, the map's sensor model.
void setSensorModelOf(const OccupancyMap& map, octomap::OcTree* tree) {
  tree->setProbHit(map.options().hit);
  tree->setProbMiss(map.options().miss);
  tree->setClampingThresMin(map.options().clamp_min);
  tree->setClampingThresMax(map.options().clamp_max);
}

// The same points into the map and, through octomap's own discretised insertion, the tree.
void insertIntoBoth(const Vector3d& origin, const std::vector<Vector3d>& points, OccupancyMap* map,
                    octomap::OcTree* tree, bool tree_lazy_eval) {
  octomap::Pointcloud cloud;
  for (const Vector3d& p : points) cloud.push_back(p.x(), p.y(), p.z());
  map->insert(origin, points);
  tree->insertPointCloud(cloud, octomap::point3d(origin.x(), origin.y(), origin.z()),
                         map->options().max_range, tree_lazy_eval, /*discretize=*/true);
}

// The map's tree, log-odds and all (the full .ot format), against `reference` filled by
// octomap's own lazy insertion, once its inner nodes are updated and pruned as the map's are.
void expectOctomapsOwnTree(const OccupancyMap& map, octomap::OcTree* reference) {
  reference->updateInnerOccupancy();
  reference->prune();
  std::ostringstream ours, theirs;
  map.tree().write(ours);
  reference->write(theirs);
  EXPECT_EQ(ours.str(), theirs.str());
}
}  // namespace

TEST(OccupancyMap, SampledSegmentIsOccupiedAndRaysAreFree) {
  OccupancyMap map;  // 5 cm
  KeyframeLandmarks kf = keyframeAtOrigin();
  kf.lines.push_back({1, Vector3d(2.01, -0.5, 0.01), Vector3d(2.01, 0.5, 0.01), 5});
  map.insertKeyframe(kf);
  for (double y = -0.5; y <= 0.5; y += 0.025)
    EXPECT_TRUE(map.isOccupied(Vector3d(2.01, y, 0.01))) << "y = " << y;
  // On the rays from the camera: free. Behind the segment, or off the rays: unknown.
  for (double x : {0.3, 1.0, 1.5, 1.85}) EXPECT_TRUE(map.isFree(Vector3d(x, 0, 0.01))) << x;
  EXPECT_TRUE(map.isFree(Vector3d(1.0, 0.2, 0.01)));
  EXPECT_FALSE(map.occupancy(Vector3d(2.5, 0, 0.01)).has_value());
  EXPECT_FALSE(map.occupancy(Vector3d(1.0, 0, 1.0)).has_value());
  const VoxelCounts c = map.counts();
  EXPECT_GE(c.occupied, 20u);
  EXPECT_LE(c.occupied, 25u);  // one row of voxels, not a smear
  EXPECT_GT(c.free, 100u);
  EXPECT_NEAR(c.occupied_min.x(), 2.0, 1e-6);
  EXPECT_NEAR(c.occupied_max.x(), 2.05, 1e-6);
}

TEST(OccupancyMap, RepeatedMissesClearAVoxel) {
  OccupancyMap map;
  map.insert(Vector3d::Zero(), {Vector3d(1.02, 0.02, 0.02)});
  ASSERT_TRUE(map.isOccupied(Vector3d(1.02, 0.02, 0.02)));
  // Seen through: in log-odds a hit (0.7) is +0.85 and a miss (0.4) -0.41, so two misses
  // leave it occupied and the third clears it.
  map.insert(Vector3d::Zero(), {Vector3d(2.02, 0.02, 0.02)});
  map.insert(Vector3d::Zero(), {Vector3d(2.02, 0.02, 0.02)});
  EXPECT_TRUE(map.isOccupied(Vector3d(1.02, 0.02, 0.02)));
  map.insert(Vector3d::Zero(), {Vector3d(2.02, 0.02, 0.02)});
  EXPECT_TRUE(map.isFree(Vector3d(1.02, 0.02, 0.02)));
}

TEST(OccupancyMap, MaxRangeAndMinObservationsAndNoCarving) {
  OccupancyMapOptions o;
  o.max_range = 5;
  o.resolution = 0.1;
  OccupancyMap map(o);
  EXPECT_DOUBLE_EQ(map.tree().getResolution(), 0.1);
  EXPECT_NEAR(map.tree().getProbHit(), 0.7, 1e-6);
  map.insert(Vector3d::Zero(), {Vector3d(10.05, 0.05, 0.05)});
  EXPECT_FALSE(map.isOccupied(Vector3d(10.05, 0.05, 0.05)));
  EXPECT_TRUE(map.isFree(Vector3d(4.5, 0.05, 0.05)));
  EXPECT_FALSE(map.occupancy(Vector3d(6.05, 0.05, 0.05)).has_value());

  KeyframeLandmarks kf = keyframeAtOrigin();
  kf.lines.push_back({1, Vector3d(2, -0.5, 0.05), Vector3d(2, 0.5, 0.05), 1});  // too rare
  map.insertKeyframe(kf);
  EXPECT_EQ(map.counts().occupied, 0u);

  OccupancyMapOptions no_carve;
  no_carve.carve_free_space = false;
  OccupancyMap hits_only(no_carve);
  KeyframeLandmarks kf2 = keyframeAtOrigin();
  kf2.points.push_back({1, Vector3d(1, 1, 1)});
  hits_only.insertKeyframe(kf2);
  EXPECT_EQ(hits_only.counts().occupied, 1u);
  EXPECT_EQ(hits_only.counts().free, 0u);
}

TEST(OccupancyMap, OptionsUseOctomapServerNames) {
  const YamlReader y = YamlReader::fromString(
      "mapping:\n  octomap:\n    resolution: 0.1\n    sensor_model_hit: 0.8\n"
      "    sensor_model_miss: 0.3\n    sensor_model_min: 0.1\n    sensor_model_max: 0.95\n"
      "    sensor_model_max_range: 6\n",
      "t.yaml");
  const OccupancyMapOptions o = OccupancyMapOptions::load(y, "mapping.octomap");
  EXPECT_DOUBLE_EQ(o.resolution, 0.1);
  EXPECT_DOUBLE_EQ(o.max_range, 6);
  OccupancyMap map(o);
  EXPECT_NEAR(map.tree().getProbHit(), 0.8, 1e-6);
  EXPECT_NEAR(map.tree().getProbMiss(), 0.3, 1e-6);
  EXPECT_NEAR(map.tree().getClampingThresMin(), 0.1, 1e-6);
  EXPECT_NEAR(map.tree().getClampingThresMax(), 0.95, 1e-6);
  const YamlReader bad =
      YamlReader::fromString("mapping:\n  octomap:\n    sensor_model_hit: 0.3\n", "t.yaml");
  EXPECT_THROW(OccupancyMapOptions::load(bad, "mapping.octomap"), Error);
}

// Insertions are lazy (inner nodes updated when the tree is read): the result must be the
// tree that OctoMap's eager insertion builds from the same rays.
TEST(OccupancyMap, LazyInsertionBuildsTheEagerTree) {
  OccupancyMap map;
  octomap::OcTree eager(map.options().resolution);
  setSensorModelOf(map, &eager);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 30; ++k) {
    const Vector3d origin(0.1 * k, 0.3 * u(rng), 0.2 * u(rng));
    std::vector<Vector3d> points;
    for (int i = 0; i < 200; ++i)
      // A wall at x = 4 and a floor at z = -1, seen again and again from moving cameras.
      points.push_back(i % 2 ? Vector3d(4.0, 3 * u(rng), u(rng))
                             : Vector3d(0.1 * k + 2 * u(rng), 2 * u(rng), -1.0));
    insertIntoBoth(origin, points, &map, &eager, /*tree_lazy_eval=*/false);
  }
  std::ostringstream lazy_bytes, eager_bytes;
  map.tree().writeBinaryConst(lazy_bytes);
  eager.writeBinaryConst(eager_bytes);
  EXPECT_EQ(lazy_bytes.str(), eager_bytes.str());
  EXPECT_EQ(map.tree().size(), eager.size());
  EXPECT_GT(map.counts().occupied, 100u);
}

TEST(OccupancyMap, InPlaceUpdatesGiveOctomapsOwnLogOdds) {
  // Against octomap's own insertPointCloud, log-odds and all (the full .ot format), with the
  // tree pruned halfway so that later rays also meet pruned nodes.
  OccupancyMap map;
  octomap::OcTree reference(map.options().resolution);
  setSensorModelOf(map, &reference);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 40; ++k) {
    const Vector3d origin(0.05 * k, 0.3 * u(rng), 0.2 * u(rng));
    std::vector<Vector3d> points;
    for (int i = 0; i < 150; ++i)
      // Enough repeats of the same wall and floor to clamp many voxels.
      points.push_back(i % 2 ? Vector3d(3.0, 2 * u(rng), 0.5 * u(rng))
                             : Vector3d(1.5 + u(rng), 1.5 * u(rng), -1.0));
    insertIntoBoth(origin, points, &map, &reference, /*tree_lazy_eval=*/true);
    if (k == 20) {
      ASSERT_GT(map.tree().size(), 0u);  // reading the tree updates and prunes it
      reference.updateInnerOccupancy();
      reference.prune();
    }
  }
  expectOctomapsOwnTree(map, &reference);
  EXPECT_GT(map.counts().occupied, 50u);
}

TEST(OccupancyMap, CutRaysGiveOctomapsOwnTree) {
  // With a range limit, points beyond it only carve free space up to the range: against
  // octomap's own insertPointCloud, log-odds and all.
  OccupancyMapOptions options;
  options.max_range = 2.5;
  OccupancyMap map(options);
  octomap::OcTree reference(map.options().resolution);
  setSensorModelOf(map, &reference);
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 15; ++k) {
    const Vector3d origin(0.1 * k, 0.3 * u(rng), 0.2 * u(rng));
    std::vector<Vector3d> points;
    for (int i = 0; i < 120; ++i)
      // A wall at 2 m (within range) and one at 4 m (beyond it), with repeats in one voxel.
      points.push_back(i % 3 == 0   ? Vector3d(0.1 * k + 2.0, u(rng), 0.5 * u(rng))
                       : i % 3 == 1 ? Vector3d(0.1 * k + 4.0, 2 * u(rng), u(rng))
                                    : Vector3d(0.1 * k + 2.0, 0.01, 0.01));
    insertIntoBoth(origin, points, &map, &reference, /*tree_lazy_eval=*/true);
  }
  expectOctomapsOwnTree(map, &reference);
  EXPECT_GT(map.counts().occupied, 20u);
  EXPECT_FALSE(map.isOccupied(Vector3d(4.05, 0.0, 0.0)));  // beyond the range: never occupied
}
