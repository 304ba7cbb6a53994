// LineMap: updates by landmark ID, merging of collinear overlapping segments of
// different IDs (and not of offset, angled or disjoint ones), save-time filtering,
// pruning, folding, options.
#include <gtest/gtest.h>

#include <random>

#include "alvio/common/error.h"
#include "alvio/config/yaml_reader.h"
#include "alvio/mapping/line_map.h"

using namespace alvio;
using Eigen::Vector3d;

namespace {
const Vector3d kCamera(0, -3, 0);

LineMapOptions keepAll() {
  LineMapOptions o;
  o.min_observations = 1;
  o.min_length_m = 0;
  return o;
}
}  // namespace

TEST(LineMap, SameIdUpdatesLatestEstimateAndUnitesExtent) {
  LineMap map(keepAll());
  ASSERT_TRUE(map.addSegment(7, Vector3d(0, 0, 0), Vector3d(1, 0, 0), 3, kCamera));
  // Re-observed: the line moved by 1 cm, the extent now reaches x = 2.
  ASSERT_TRUE(map.addSegment(7, Vector3d(0.5, 0.01, 0), Vector3d(2, 0.01, 0), 5, kCamera));
  ASSERT_EQ(map.size(), 1u);
  EXPECT_EQ(map.landmarkCount(), 1u);
  const MapLine l = map.lines().front();
  EXPECT_NEAR(std::min(l.p0.x(), l.p1.x()), 0.0, 1e-9);  // union of the extents
  EXPECT_NEAR(std::max(l.p0.x(), l.p1.x()), 2.0, 1e-9);
  EXPECT_NEAR(l.p0.y(), 0.01, 1e-9);  // the latest estimate, not an average
  EXPECT_NEAR(l.p1.y(), 0.01, 1e-9);
  EXPECT_EQ(l.observations, 5);  // cumulative per ID: replaced, not added
  EXPECT_EQ(l.landmarks, 1);
  EXPECT_EQ(map.mergeCount(), 0u);
}

TEST(LineMap, SameIdFarAwayDropsTheStaleExtent) {
  LineMap map(keepAll());
  map.addSegment(1, Vector3d(0, 0, 0), Vector3d(1, 0, 0), 3, kCamera);
  map.addSegment(1, Vector3d(5, 1, 0), Vector3d(6, 1, 0), 4, kCamera);
  ASSERT_EQ(map.size(), 1u);
  const MapLine l = map.lines().front();
  EXPECT_NEAR(l.length(), 1.0, 1e-9);
  EXPECT_NEAR(l.p0.y(), 1.0, 1e-9);
}

TEST(LineMap, MergesCollinearOverlappingSegmentsOfDifferentIds) {
  LineMap map(keepAll());
  map.addSegment(1, Vector3d(0, 0, 0), Vector3d(2, 0, 0), 10, kCamera);
  // 2 cm off and 0.5 deg tilted, overlapping [1.5, 2].
  const double a = 0.5 * M_PI / 180;
  map.addSegment(2, Vector3d(1.5, 0.02, 0), Vector3d(1.5 + 2 * std::cos(a), 0.02, 2 * std::sin(a)),
                 6, kCamera);
  ASSERT_EQ(map.size(), 1u);
  EXPECT_EQ(map.mergeCount(), 1u);
  const MapLine l = map.lines().front();
  EXPECT_EQ(l.observations, 16);
  EXPECT_EQ(l.landmarks, 2);
  EXPECT_NEAR(l.length(), 3.5, 0.02);
  ASSERT_TRUE(map.lineOf(1) && map.lineOf(2));
  EXPECT_EQ(map.lineOf(1)->id, map.lineOf(2)->id);
  // A third one, reversed direction, inside the extent: still one line.
  map.addSegment(3, Vector3d(3.0, 0.01, 0.01), Vector3d(0.5, 0.0, 0), 2, kCamera);
  EXPECT_EQ(map.size(), 1u);
  EXPECT_EQ(map.lines().front().observations, 18);
}

TEST(LineMap, AMergedLineCarriesItsBestPlacedLandmarksUncertainty) {
  LineMap map(keepAll());
  map.addSegment(1, Vector3d(0, 0, 0), Vector3d(2, 0, 0), 10, kCamera);  // unknown
  EXPECT_LT(map.lines().front().midpoint_std_m, 0);
  map.addSegment(2, Vector3d(1, 0.01, 0), Vector3d(3, 0.01, 0), 6, kCamera, 0.02);
  map.addSegment(3, Vector3d(2, 0.0, 0), Vector3d(4, 0.0, 0), 6, kCamera, 0.03);
  ASSERT_EQ(map.size(), 1u);
  EXPECT_DOUBLE_EQ(map.lines().front().midpoint_std_m, 0.02);
  // Landmark 2 re-estimated less certainly: its latest estimate counts.
  map.addSegment(2, Vector3d(1, 0.01, 0), Vector3d(3, 0.01, 0), 8, kCamera, 0.04);
  ASSERT_EQ(map.size(), 1u);
  EXPECT_DOUBLE_EQ(map.lines().front().midpoint_std_m, 0.03);
}

TEST(LineMap, UncertaintySummaryCountsTheLinesUnderOneCentimetre) {
  std::vector<MapLine> lines(4);
  const double sigma[] = {0.004, 0.008, 0.02, -1};  // the last one unknown
  for (int i = 0; i < 4; ++i) {
    lines[i].p1 = Vector3d(i + 1.0, 0, 0);  // 1, 2, 3 and 4 m long
    lines[i].midpoint_std_m = sigma[i];
  }
  EXPECT_EQ(describeLineUncertainty(lines),
            "midpoint uncertainty (1 sigma): median 8.0 mm; 2 of 4 lines (3.0 m of 10.0) under "
            "1 cm");
  for (MapLine& l : lines) l.midpoint_std_m = -1;
  EXPECT_EQ(describeLineUncertainty(lines), "");
}

TEST(LineMap, DoesNotMergeParallelOffsetAngledOrDisjointSegments) {
  LineMap map(keepAll());
  map.addSegment(1, Vector3d(0, 0, 0), Vector3d(2, 0, 0), 10, kCamera);
  map.addSegment(2, Vector3d(0, 0.2, 0), Vector3d(2, 0.2, 0), 10, kCamera);  // parallel, 20 cm
  map.addSegment(3, Vector3d(2.3, 0, 0), Vector3d(4, 0, 0), 10, kCamera);    // collinear, gap
  const double a = 10 * M_PI / 180;  // crosses line 1 at x = 1, 10 deg apart
  map.addSegment(4, Vector3d(1 - std::cos(a), -std::sin(a), 0),
                 Vector3d(1 + std::cos(a), std::sin(a), 0), 10, kCamera);
  EXPECT_EQ(map.size(), 4u);
  EXPECT_EQ(map.mergeCount(), 0u);
}

TEST(LineMap, RepeatedWallsWithNewIdsKeepTheLineCountBounded) {
  // 40 well-separated lines, each reported 50 times under fresh IDs with noise and random
  // overlapping sub-extents: the map must end with 40 lines.
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0, 0.005);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<std::pair<Vector3d, Vector3d>> truth;
  for (int i = 0; i < 40; ++i) {
    const Vector3d c(2.0 * (i % 5), 2.0 * ((i / 5) % 4), 3.0 * (i / 20));
    Vector3d d(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
    truth.emplace_back(c, d.normalized());
  }
  LineMap map(keepAll());
  int id = 0;
  for (int round = 0; round < 50; ++round)
    for (const auto& [c, d] : truth) {
      const double t0 = -0.8 * u(rng) - 0.1, t1 = 0.8 * u(rng) + 0.1;  // always covers c
      map.addSegment(id++, c + t0 * d + Vector3d(n(rng), n(rng), n(rng)),
                     c + t1 * d + Vector3d(n(rng), n(rng), n(rng)), 3, kCamera);
    }
  EXPECT_EQ(map.size(), truth.size());
  // Folding keeps the remembered IDs per line within the budget.
  EXPECT_LE(map.landmarkCount(), truth.size() * map.options().max_members_per_line);
  for (const MapLine& l : map.lines()) EXPECT_EQ(l.observations, 150);
}

TEST(LineMap, DropsRareShortLongAndFarLinesAtSave) {
  LineMapOptions o;
  o.min_observations = 4;
  o.min_length_m = 0.1;
  o.max_length_m = 30;
  o.max_depth_m = 20;
  LineMap map(o);
  map.addSegment(1, Vector3d(0, 0, 0), Vector3d(2, 0, 0), 10, kCamera);     // kept
  map.addSegment(2, Vector3d(0, 1, 0), Vector3d(2, 1, 0), 2, kCamera);      // too rare
  map.addSegment(3, Vector3d(0, 2, 0), Vector3d(0.05, 2, 0), 10, kCamera);  // too short
  map.addSegment(4, Vector3d(0, 3, 0), Vector3d(50, 3, 0), 10, kCamera);    // too long
  map.addSegment(5, Vector3d(0, 40, 0), Vector3d(2, 40, 0), 10, kCamera);   // too far
  EXPECT_EQ(map.size(), 5u);  // nothing is deleted while mapping
  const auto kept = map.filteredLines();
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept.front().id, map.lineOf(1)->id);
  // Seen again under a new ID: the rare line reaches the threshold and is kept.
  map.addSegment(6, Vector3d(0.5, 1.0, 0), Vector3d(1.5, 1.0, 0), 2, kCamera);
  EXPECT_EQ(map.filteredLines().size(), 2u);
}

TEST(LineMap, MinLandmarksKeepsOnlyLinesASecondTrackConfirmed) {
  LineMapOptions o;
  o.min_observations = 1;
  o.min_landmarks = 2;
  LineMap map(o);
  map.addSegment(1, Vector3d(0, 0, 0), Vector3d(2, 0, 0), 50, kCamera);  // one track only
  map.addSegment(2, Vector3d(0, 1, 0), Vector3d(2, 1, 0), 5, kCamera);
  map.addSegment(3, Vector3d(0.5, 1.01, 0), Vector3d(1.8, 1.01, 0), 5, kCamera);  // confirms 2
  const auto kept = map.filteredLines();
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept.front().landmarks, 2);
  EXPECT_EQ(kept.front().id, map.lineOf(2)->id);
}

TEST(LineMap, PrunesStaleWeakLines) {
  LineMapOptions o;
  o.prune_weak_after_keyframes = 20;
  LineMap map(o);
  map.beginKeyframe();
  map.addSegment(1, Vector3d(0, 0, 0), Vector3d(1, 0, 0), 1, kCamera);   // weak
  map.addSegment(2, Vector3d(0, 1, 0), Vector3d(1, 1, 0), 10, kCamera);  // strong
  for (int k = 0; k < 40; ++k) map.beginKeyframe();
  EXPECT_EQ(map.size(), 1u);
  EXPECT_EQ(map.prunedCount(), 1u);
  EXPECT_FALSE(map.lineOf(1).has_value());
  EXPECT_TRUE(map.lineOf(2).has_value());
}

TEST(LineMap, IgnoresDegenerateSegments) {
  LineMap map;
  EXPECT_FALSE(map.addSegment(1, Vector3d(1, 1, 1), Vector3d(1, 1, 1), 5, kCamera));
  EXPECT_FALSE(map.addSegment(2, Vector3d(0, 0, NAN), Vector3d(1, 1, 1), 5, kCamera));
  EXPECT_EQ(map.size(), 0u);
}

TEST(LineMap, OptionsLoadFromYamlAndNameBadKeys) {
  const YamlReader ok = YamlReader::fromString(
      "mapping:\n  lines:\n    merge_angle_deg: 5\n    min_observations: 7\n    min_landmarks: 2\n",
      "test.yaml");
  const LineMapOptions o = LineMapOptions::load(ok, "mapping.lines");
  EXPECT_DOUBLE_EQ(o.merge_angle_deg, 5);
  EXPECT_EQ(o.min_observations, 7);
  EXPECT_EQ(o.min_landmarks, 2);
  EXPECT_DOUBLE_EQ(o.merge_distance_m, LineMapOptions().merge_distance_m);
  const YamlReader bad =
      YamlReader::fromString("mapping:\n  lines:\n    merge_angle_deg: 95\n", "bad.yaml");
  try {
    LineMapOptions::load(bad, "mapping.lines");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("mapping.lines.merge_angle_deg"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos) << e.what();
  }
}
