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

TEST(MapBuilder, PointsSeenWithTooLittleParallaxStayOut) {
  MappingOptions o;
  o.min_point_parallax_deg = 2.0;
  MapBuilder map(o);
  KeyframeLandmarks kf;
  kf.points = {{1, {2, 0, 0}, 0.5}, {2, {0, 2, 0}, 5.0}, {3, {0, 0, 2}, -1.0}};
  map.addKeyframe(kf);
  EXPECT_EQ(map.points().count(1), 0u);  // too little parallax
  EXPECT_EQ(map.points().count(2), 1u);
  EXPECT_EQ(map.points().count(3), 1u);  // unknown parallax: kept
  EXPECT_FALSE(map.occupancyMap().isOccupied({2, 0, 0}));
  EXPECT_TRUE(map.occupancyMap().isOccupied({0, 2, 0}));
  EXPECT_TRUE(map.occupancyMap().isOccupied({0, 0, 2}));
}

TEST(MapBuilder, LinesOfUncertainOrUnknownDirectionStayOut) {
  MappingOptions o;
  o.max_line_direction_std_deg = 2.0;
  MapBuilder map(o);
  KeyframeLandmarks kf;
  kf.lines = {{5, {0, 0, 1}, {2, 0, 1}, 6, 0.5},
              {6, {0, 1, 1}, {0, 3, 1}, 9, 3.0},    // too uncertain
              {7, {1, 1, 2}, {3, 1, 2}, 9, -1.0}};  // not computed
  map.addKeyframe(kf);
  EXPECT_EQ(map.summary().lines, 1u);
  EXPECT_EQ(map.summary().keyframes, 1u);
  EXPECT_TRUE(map.occupancyMap().isOccupied({1, 0, 1}));
  EXPECT_FALSE(map.occupancyMap().isOccupied({0, 2, 1}));
  EXPECT_FALSE(map.occupancyMap().isOccupied({2, 1, 2}));
  // A report of retiring lines that all stay out is not a keyframe for the map.
  kf.lines = {{8, {0, 0, 3}, {2, 0, 3}, 6, 2.5}};
  map.addKeyframe(kf);
  EXPECT_EQ(map.summary().keyframes, 1u);
  EXPECT_EQ(map.summary().lines, 1u);
}

TEST(EstimatorKeyframeFeed, ReportsOldestKeyframeLandmarksOnce) {
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
    auto kf = feed.poll(estimator);
    EXPECT_FALSE(feed.poll(estimator).has_value()) << "reported the same keyframe twice";
    if (!kf) continue;
    // Exactly the estimator's landmarks anchored in its oldest keyframe, seen from there.
    const auto window = estimator.windowStates();
    EXPECT_DOUBLE_EQ(kf->t, window.front().t);
    EXPECT_LT((kf->T_w_c.translation() -
               (window.front().p + window.front().q * c.camera.T_b_c.translation()))
                  .norm(),
              1e-9);
    const auto positions = estimator.landmarkPositions();
    std::size_t anchored = 0;
    for (const auto& [id, p] : positions)
      if (estimator.points().landmarks().at(id).start_frame == 0) ++anchored;
    EXPECT_EQ(kf->points.size(), anchored);
    for (const LandmarkPoint& p : kf->points) {
      EXPECT_LT((positions.at(p.id) - p.p_w).norm(), 1e-12);
      EXPECT_GE(p.parallax_deg, 0.0);
      EXPECT_LT(p.parallax_deg, 90.0);
      EXPECT_GT((kf->T_w_c.inverse() * p.p_w).z(), 0.0) << "behind the reporting camera";
    }
    keyframes.push_back(*kf);
  }
  ASSERT_GT(keyframes.size(), 20u);
  EXPECT_FALSE(feed.flush(estimator).empty());

  // Against the truth: align the keyframe body positions (after the first 4 s, once the
  // estimator has settled) and measure how far the landmarks lie from the walls of the
  // scenario's 12 x 12 x 5 m room (x, y = +-6, z = -1 or 4). Landmark accuracy is the
  // estimator's; this checks that the feed hands over world-frame positions.
  Points3 est, truth;
  const Trajectory gt = scenario.groundTruth();
  std::vector<const KeyframeLandmarks*> settled;
  for (const auto& kf : keyframes) {
    if (kf.t < keyframes.front().t + 4) continue;
    auto it =
        std::min_element(gt.begin(), gt.end(), [&](const StampedPose& a, const StampedPose& b) {
          return std::abs(a.t - kf.t) < std::abs(b.t - kf.t);
        });
    ASSERT_LT(std::abs(it->t - kf.t), 1e-3);
    est.push_back((kf.T_w_c * c.camera.T_b_c.inverse()).translation());
    truth.push_back(it->p);
    settled.push_back(&kf);
  }
  ASSERT_GT(settled.size(), 10u);
  // A moving camera: the settled keyframes' points were seen with parallax.
  double max_parallax = 0;
  for (const KeyframeLandmarks* kf : settled)
    for (const LandmarkPoint& p : kf->points) max_parallax = std::max(max_parallax, p.parallax_deg);
  EXPECT_GT(max_parallax, 2.0);
  const Similarity3 align = alignPoints(est, truth, AlignmentMode::kSE3);
  for (std::size_t i = 0; i < est.size(); ++i)
    EXPECT_LT((align.apply(est[i]) - truth[i]).norm(), 0.1);
  std::vector<double> d;
  for (const KeyframeLandmarks* kf : settled)
    for (const LandmarkPoint& p : kf->points) {
      const Eigen::Vector3d q = align.apply(p.p_w);
      d.push_back(std::min({std::abs(std::abs(q.x()) - 6), std::abs(std::abs(q.y()) - 6),
                            std::abs(q.z() + 1), std::abs(q.z() - 4)}));
    }
  ASSERT_GT(d.size(), 200u);
  std::sort(d.begin(), d.end());
  std::cout << d.size() << " landmarks: distance to the nearest wall median " << d[d.size() / 2]
            << " m, 75th percentile " << d[d.size() * 3 / 4] << " m\n";
  EXPECT_LT(d[d.size() / 2], 0.1);
  EXPECT_LT(d[d.size() * 3 / 4], 0.2);
}
