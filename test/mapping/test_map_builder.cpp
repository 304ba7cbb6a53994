// MapBuilder end to end on the synthetic room (line count bounded over repeated laps,
// precision/recall, occupancy near the walls), its options, and the estimator feed
// on the estimator's own synthetic scenario.
#include <gtest/gtest.h>

#include "alvio/common/logging.h"
#include "alvio/config/config.h"
#include "alvio/config/yaml_reader.h"
#include "alvio/estimator/estimator.h"
#include "alvio/eval/alignment.h"
#include "alvio/mapping/estimator_keyframe_feed.h"
#include "alvio/mapping/map_builder.h"
#include "alvio/mapping/map_evaluation.h"
#include "alvio/mapping/synthetic_room.h"
#include "synthetic_scenario.h"
#include "test_support.h"

using namespace alvio;

TEST(MapBuilder, SyntheticRoomLapsKeepLinesBoundedAndAccurate) {
  SyntheticRoomOptions ro;
  ro.laps = 4;
  ro.keyframes_per_lap = 40;
  const SyntheticRoom room = makeSyntheticRoom(ro);
  MapBuilder map;
  std::vector<std::size_t> lines_per_lap;
  for (int lap = 0; lap < ro.laps; ++lap) {
    for (int k = 0; k < ro.keyframes_per_lap; ++k)
      map.addKeyframe(room.keyframes[lap * ro.keyframes_per_lap + k]);
    lines_per_lap.push_back(map.lineMap().filteredLines().size());
  }
  const MapSummary s = map.summary();
  std::cout << s.toString();
  // New IDs every lap, but the same 28 edges: the kept line count stays put.
  EXPECT_LE(lines_per_lap.back(), lines_per_lap.front() + 5);
  EXPECT_LE(lines_per_lap.back(), room.edges.size() + 12);
  EXPECT_GT(s.merges, 100u);
  std::vector<Segment3> kept;
  for (const MapLine& l : map.lineMap().filteredLines()) kept.push_back(l.segment());
  const LineMapEvaluation le = evaluateLineMap(kept, room.edges, 0.10, 3 * M_PI / 180);
  EXPECT_GE(le.precision, 0.95);
  EXPECT_GE(le.recall, 0.8);
  const OccupancyEvaluation oe = evaluateOccupancy(
      map.occupancyMap().tree(), [&](const Eigen::Vector3d& p) { return room.surfaceDistance(p); },
      2 * map.occupancyMap().options().resolution);
  EXPECT_GE(oe.fraction, 0.95);
  EXPECT_GT(s.voxels.free, s.voxels.occupied);
  EXPECT_TRUE(s.has_extent);
  EXPECT_LT((s.extent_max - room.size).cwiseAbs().maxCoeff(), 0.2);
}

TEST(MapBuilder, OptionsFromTheShippedConfigWithoutUnknownKeyWarnings) {
  std::vector<std::string> warnings;
  setLogSink([&](LogLevel level, const std::string& m) {
    if (level >= LogLevel::kWarn) warnings.push_back(m);
  });
  const std::string path = test::sourcePath("config/euroc.yaml");
  Config::load(path);
  const MappingOptions o = MappingOptions::load(YamlReader(path), "mapping");
  setLogSink(nullptr);
  for (const std::string& w : warnings) ADD_FAILURE() << "warning: " << w;
  EXPECT_TRUE(o.enabled);
  EXPECT_DOUBLE_EQ(o.octomap.resolution, 0.05);
  EXPECT_DOUBLE_EQ(o.octomap.hit, 0.7);
  EXPECT_DOUBLE_EQ(o.octomap.miss, 0.4);
  EXPECT_DOUBLE_EQ(o.octomap.clamp_min, 0.12);
  EXPECT_DOUBLE_EQ(o.octomap.clamp_max, 0.97);

  // A misspelt key under mapping: is reported.
  warnings.clear();
  setLogSink([&](LogLevel, const std::string& m) { warnings.push_back(m); });
  MappingOptions::load(
      YamlReader::fromString("mapping:\n  octomap:\n    resolutoin: 0.1\n", "t.yaml"), "mapping");
  setLogSink(nullptr);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings.front().find("mapping.octomap.resolutoin"), std::string::npos);
}

TEST(EstimatorKeyframeFeed, ReportsOldestKeyframeLandmarksOnTheWalls) {
  const Config c = Config::load(test::sourcePath("config/euroc.yaml"));
  test::ScenarioOptions so;
  so.duration_s = 10;
  const test::SyntheticScenario scenario(so, c.camera, c.imu);
  Estimator estimator(c.estimator, c.camera, c.imu);
  EstimatorKeyframeFeed feed(c.camera.T_b_c);
  std::vector<KeyframeLandmarks> keyframes;
  std::size_t next_imu = 0;
  const auto& imu = scenario.imu();
  for (const auto& frame : scenario.frames()) {
    while (next_imu < imu.size() && imu[next_imu].t_ns <= frame.t_ns)
      estimator.addImu(imu[next_imu++]);
    if (next_imu < imu.size()) estimator.addImu(imu[next_imu++]);
    estimator.addFrame(frame);
    if (auto kf = feed.poll(estimator)) keyframes.push_back(*kf);
    EXPECT_FALSE(feed.poll(estimator).has_value()) << "reported the same keyframe twice";
  }
  const auto rest = feed.flush(estimator);
  ASSERT_GT(keyframes.size(), 20u);
  EXPECT_FALSE(rest.empty());
  // Align the estimated keyframe camera centres with the truth, then the landmarks must
  // lie on the walls of the scenario's 12 x 12 x 5 m room (x, y = +-6, z = -1 or 4).
  Points3 est, truth;
  const Trajectory gt = scenario.groundTruth();
  for (const auto& kf : keyframes) {
    auto it = std::min_element(gt.begin(), gt.end(), [&](const StampedPose& a, const StampedPose& b) {
      return std::abs(a.t - kf.t) < std::abs(b.t - kf.t);
    });
    ASSERT_LT(std::abs(it->t - kf.t), 1e-3);
    est.push_back((kf.T_w_c * c.camera.T_b_c.inverse()).translation());
    truth.push_back(it->p);
  }
  const Similarity3 align = alignPoints(est, truth, AlignmentMode::kSe3);
  std::size_t n = 0, on_wall = 0;
  for (const auto& kf : keyframes) {
    ASSERT_FALSE(kf.points.empty());
    for (const LandmarkPoint& p : kf.points) {
      // In front of the keyframe camera that reports it.
      EXPECT_GT((kf.T_w_c.inverse() * p.p_w).z(), 0.0);
      const Eigen::Vector3d q = align.apply(p.p_w);
      const double d = std::min({std::abs(std::abs(q.x()) - 6), std::abs(std::abs(q.y()) - 6),
                                 std::abs(q.z() + 1), std::abs(q.z() - 4)});
      ++n;
      if (d < 0.2) ++on_wall;
    }
  }
  EXPECT_GT(static_cast<double>(on_wall) / n, 0.95) << on_wall << " of " << n;
}
