// A map against the true scene: the nearest-edge line errors, and the whole evaluation on a map
// given in a frame rotated and shifted from the truth (as an estimate's world is).
#include <gtest/gtest.h>

#include "alvio/mapping/map_truth_evaluation.h"
#include "alvio/mapping/occupancy_map.h"

using namespace alvio;
using Eigen::Vector3d;

TEST(MapTruth, NearestEdgeIsTheAlignedOneNotTheCornerNeighbour) {
  // Two edges meeting at the origin; a line along the x edge, 3 cm above it, tilted 2 deg,
  // starting near the corner.
  const std::vector<Segment3> edges = {{Vector3d(0, 0, 0), Vector3d(0, 2, 0)},
                                       {Vector3d(0, 0, 0), Vector3d(4, 0, 0)}};
  const double tilt = 2 * M_PI / 180;
  const Vector3d mid(0.6, 0, 0.03), u(std::cos(tilt), 0, std::sin(tilt));
  const Segment3 line{mid - 0.5 * u, mid + 0.5 * u};
  const LineError e = lineErrorToNearestEdge(line, edges);
  EXPECT_EQ(e.edge, 1);
  EXPECT_NEAR(e.angle_deg, 2.0, 1e-9);
  EXPECT_NEAR(e.midpoint_distance_m, 0.03, 1e-9);
}

TEST(MapTruth, MapInAnotherFrameIsScoredAfterTheAlignment) {
  // Truth: the 12 edges of a 2 x 2 x 2 m box with its surfaces.
  std::vector<Segment3> edges;
  for (int axis = 0; axis < 3; ++axis)
    for (int i = 0; i < 4; ++i) {
      Vector3d a = Vector3d::Zero();
      a[(axis + 1) % 3] = 2.0 * (i & 1);
      a[(axis + 2) % 3] = 2.0 * (i >> 1);
      Vector3d b = a;
      b[axis] = 2;
      edges.push_back({a, b});
    }
  auto surface = [](const Vector3d& p) {
    const Vector3d c = p.cwiseMax(Vector3d::Zero()).cwiseMin(Vector3d::Constant(2));
    if ((c - p).norm() > 0) return (c - p).norm();  // outside the box
    return std::min(c.minCoeff(), (Vector3d::Constant(2) - c).minCoeff());
  };
  // The estimate's frame: truth = T_gt_est * est.
  Similarity3 T_gt_est;
  T_gt_est.R = Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  T_gt_est.t = Vector3d(5, -3, 1);
  auto toEst = [&](const Vector3d& p) {
    return Vector3d(T_gt_est.R.transpose() * (p - T_gt_est.t));
  };
  std::vector<Segment3> lines;
  for (const Segment3& e : edges) lines.push_back({toEst(e.p0), toEst(e.p1)});  // 24 m, exact
  lines.push_back({toEst(Vector3d(1, 1, 1)), toEst(Vector3d(1, 1, 1.6))});      // 0.6 m inside
  // Occupied voxels: 40 on the floor (z = 0 face), 10 floating inside the box's middle.
  OccupancyMapOptions o;
  o.carve_free_space = false;
  OccupancyMap map(o);
  std::vector<Vector3d> pts;
  for (int i = 0; i < 40; ++i) pts.push_back(toEst(Vector3d(0.1 + 0.045 * i, 0.5, 0.01)));
  for (int i = 0; i < 10; ++i) pts.push_back(toEst(Vector3d(1.0, 0.8 + 0.05 * i, 1.0)));
  map.insert(toEst(Vector3d(1, 1, 5)), pts);

  const MapTruthEvaluation m =
      evaluateMapAgainstTruth(lines, &map.tree(), T_gt_est, edges, surface, {});
  EXPECT_EQ(m.line_errors.lines, 13u);
  EXPECT_NEAR(m.line_errors.median_angle_deg, 0.0, 1e-6);
  EXPECT_NEAR(m.line_errors.median_midpoint_distance_m, 0.0, 1e-6);
  EXPECT_NEAR(m.line_map.precision, 24.0 / 24.6, 0.01);
  EXPECT_NEAR(m.line_map.recall, 1.0, 0.01);
  EXPECT_NEAR(m.line_on_surface_fraction, 24.0 / 24.6, 1e-9);  // the inner line is 0.4 m off
  const double near = static_cast<double>(m.occupancy.within_tolerance);
  EXPECT_GT(m.occupancy.occupied_voxels, 40u);
  EXPECT_NEAR(m.occupancy.fraction, near / m.occupancy.occupied_voxels, 1e-12);
  EXPECT_GT(m.occupancy.fraction, 0.7);
  EXPECT_LT(m.occupancy.fraction, 0.9);  // the floating voxels are 1 m from every face

  // Without the alignment nothing lies where it should.
  const MapTruthEvaluation wrong =
      evaluateMapAgainstTruth(lines, &map.tree(), Similarity3(), edges, surface, {});
  EXPECT_LT(wrong.line_map.precision, 0.2);
  EXPECT_GT(wrong.line_errors.median_midpoint_distance_m, 0.5);
  EXPECT_LT(wrong.occupancy.fraction, 0.2);
}
