// The map evaluation functions on cases with known answers.
#include <gtest/gtest.h>

#include "alvio/mapping/map_evaluation.h"
#include "alvio/mapping/occupancy_map.h"

using namespace alvio;
using Eigen::Vector3d;

namespace {
const double kDeg = M_PI / 180;
const std::vector<Segment3> kEdges = {{Vector3d(0, 0, 0), Vector3d(4, 0, 0)},
                                      {Vector3d(0, 0, 0), Vector3d(0, 2, 0)}};
}  // namespace

TEST(MapEvaluation, PerfectMapHasFullPrecisionAndRecall) {
  const LineMapEvaluation e = evaluateLineMap(kEdges, kEdges, 0.1, 3 * kDeg);
  EXPECT_NEAR(e.precision, 1.0, 1e-9);
  EXPECT_NEAR(e.recall, 1.0, 1e-9);
  EXPECT_NEAR(e.true_length_m, 6.0, 1e-9);
}

TEST(MapEvaluation, PrecisionIsLengthWeightedAndRecallCountsCoverage) {
  // Half of edge 0 (correct, 2 m, 5 cm off), plus a 1 m line 30 cm away (wrong).
  const std::vector<Segment3> map = {{Vector3d(0, 0.05, 0), Vector3d(2, 0.05, 0)},
                                     {Vector3d(1, 0.3, 0), Vector3d(2, 0.3, 0)}};
  const LineMapEvaluation e = evaluateLineMap(map, kEdges, 0.1, 3 * kDeg);
  EXPECT_NEAR(e.precision, 2.0 / 3.0, 0.01);
  // Covered: edge 0 up to x = 2 + sqrt(0.1^2 - 0.05^2) (the map line's end is within 10 cm);
  // edge 1 is 90 deg off every map line: not covered.
  EXPECT_NEAR(e.recall, (2.0 + std::sqrt(0.0075)) / 6.0, 0.005);
}

TEST(MapEvaluation, AngleToleranceRejectsCrossingLines) {
  // 10 deg off edge 0, crossing it at x = 2: only ~1 m near the crossing is within 10 cm,
  // and none within 3 deg.
  const double a = 10 * kDeg;
  const std::vector<Segment3> map = {{Vector3d(2 - 2 * std::cos(a), -2 * std::sin(a), 0),
                                      Vector3d(2 + 2 * std::cos(a), 2 * std::sin(a), 0)}};
  EXPECT_NEAR(evaluateLineMap(map, kEdges, 0.1, 3 * kDeg).precision, 0.0, 1e-9);
  const LineMapEvaluation loose = evaluateLineMap(map, kEdges, 0.1, 15 * kDeg);
  EXPECT_NEAR(loose.precision, 2 * 0.1 / std::sin(a) / 4.0, 0.03);
}

TEST(MapEvaluation, OccupancyFractionNearSurface) {
  OccupancyMapOptions o;
  o.carve_free_space = false;
  o.resolution = 0.1;
  OccupancyMap map(o);
  std::vector<Vector3d> pts;
  for (int i = 0; i < 30; ++i) pts.push_back(Vector3d(0.05 + 0.1 * i, 0.05, 0.05));  // on z = 0
  for (int i = 0; i < 10; ++i) pts.push_back(Vector3d(0.05 + 0.1 * i, 0.05, 1.05));  // 1 m off
  map.insert(Vector3d(0, 0, 5), pts);
  const OccupancyEvaluation e = evaluateOccupancy(
      map.tree(), [](const Vector3d& p) { return std::abs(p.z()); }, 0.2);
  EXPECT_EQ(e.occupied_voxels, 40u);
  EXPECT_EQ(e.within_tolerance, 30u);
  EXPECT_NEAR(e.fraction, 0.75, 1e-9);
  EXPECT_NEAR(e.mean_distance_m, (30 * 0.05 + 10 * 1.05) / 40, 1e-6);
}
