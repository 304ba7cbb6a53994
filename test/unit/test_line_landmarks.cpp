// The window's line landmarks: triangulation from window poses and retirement, where a line
// that left the window is refined over its history for the map.
#include <gtest/gtest.h>

#include <algorithm>

#include "alvio/estimator/line_landmarks.h"
#include "alvio/geometry/line_quality.h"
#include "line_test_utils.h"

using namespace alvio;
using alvio::test::lookAt;
using alvio::test::projectNormalised;

namespace {

const Eigen::Vector3d kP(4.0, -1.0, 0.5), kQ(4.5, 1.5, 1.8);  // a 3 m edge ~4.5 m away

// Frame k's camera: sliding sideways past the edge, looking at it.
Eigen::Isometry3d cameraAt(int k) {
  return lookAt({0.0, -0.6 + 0.15 * k, 0.2}, 0.5 * (kP + kQ));
}

// The extent's endpoints are ordered along the line's direction, not as observed.
double extentError(const LineLandmark& l) {
  return std::min(std::max((l.start_w - kP).norm(), (l.end_w - kQ).norm()),
                  std::max((l.start_w - kQ).norm(), (l.end_w - kP).norm()));
}

int64_t stamp(int k) {
  return 1000 + k;
}

// The edge, or a parallel one shifted by `offset` (a neighbouring brick joint).
std::vector<LineObservation, Eigen::aligned_allocator<LineObservation>> observeEdge(
    int k, const Eigen::Vector3d& offset = Eigen::Vector3d::Zero()) {
  LineObservation o;
  o.id = 3;
  o.start_norm = projectNormalised(cameraAt(k), kP + offset);
  o.end_norm = projectNormalised(cameraAt(k), kQ + offset);
  return {o};
}

// Eight frames see the edge; the first `unposed` leave the window without a pose (as before
// initialisation), the rest with theirs. From frame `slide_at` on, the track sees a parallel
// edge 8 cm below instead. Returns what retired through `filter`.
std::vector<LineLandmark> slideThrough(int unposed, const LineRetirementFilter& filter = {},
                                       int slide_at = 8, LineRetirementCounts* counts = nullptr) {
  LineLandmarks lines(3, LineTriangulationOptions{});
  lines.setRetirementFilter(filter);
  for (int k = 0; k < 8; ++k)
    lines.addFrame(stamp(k), observeEdge(k, k < slide_at ? Eigen::Vector3d::Zero()
                                                         : Eigen::Vector3d(0, 0, -0.08)));
  lines.triangulate([](int64_t ns) { return cameraAt(static_cast<int>(ns - 1000)); });
  EXPECT_TRUE(lines.landmarks().at(3).hasLine());
  for (int k = 0; k < 8; ++k) {
    const Eigen::Isometry3d T = cameraAt(k);
    lines.removeFrame(stamp(k), k < unposed ? nullptr : &T);
  }
  EXPECT_TRUE(lines.landmarks().empty());
  if (counts) *counts = lines.retirementCounts();
  return lines.takeRetired();
}

}  // namespace

TEST(LineLandmarks, RetiredLineIsRefinedOverItsPosedHistory) {
  const std::vector<LineLandmark> retired = slideThrough(0);
  ASSERT_EQ(retired.size(), 1u);
  EXPECT_EQ(retired[0].track_observations, 8);
  ASSERT_TRUE(retired[0].has_extent);
  EXPECT_LT(extentError(retired[0]), 1e-6);
}

TEST(LineLandmarks, FramesWithoutPoseAreLeftOutOfTheRetirement) {
  const std::vector<LineLandmark> retired = slideThrough(5);
  ASSERT_EQ(retired.size(), 1u);
  EXPECT_EQ(retired[0].track_observations, 3);
  EXPECT_LT(extentError(retired[0]), 1e-6);
  // Fewer posed views than a line needs: nothing reaches the map.
  EXPECT_TRUE(slideThrough(6).empty());
}

TEST(LineLandmarks, RetirementFilterKeepsATrackThatSlidOntoAnotherEdgeFromTheMap) {
  LineRetirementFilter filter;
  filter.max_reprojection_rms = 0.5 / 458.0;  // 0.5 px
  LineRetirementCounts counts;
  EXPECT_EQ(slideThrough(0, filter, 8, &counts).size(), 1u);  // one edge: kept
  EXPECT_EQ(counts.retired, 1);
  EXPECT_EQ(counts.held_back_fit + counts.held_back_parallax, 0);
  EXPECT_TRUE(slideThrough(0, filter, 5, &counts).empty());  // 5 views + 3 of another edge
  EXPECT_EQ(counts.held_back_fit, 1);
  EXPECT_EQ(counts.retired + counts.held_back_parallax, 0);
  EXPECT_EQ(slideThrough(0, {}, 5).size(), 1u);  // unfiltered, it would reach the map
}

TEST(LineLandmarks, RetirementFilterNeedsCameraMotionAcrossTheLine) {
  LineViews views;
  for (int k = 0; k < 8; ++k) {
    LineView v;
    v.T_w_c = cameraAt(k);
    views.push_back(v);
  }
  const double parallax = lineCrossParallax(kP, kQ, views);
  ASSERT_GT(parallax, 0.01);
  LineRetirementFilter filter;
  filter.min_cross_parallax = 0.9 * parallax;
  EXPECT_EQ(slideThrough(0, filter).size(), 1u);
  filter.min_cross_parallax = 1.1 * parallax;
  LineRetirementCounts counts;
  EXPECT_TRUE(slideThrough(0, filter, 8, &counts).empty());
  EXPECT_EQ(counts.held_back_parallax, 1);
  EXPECT_EQ(counts.retired + counts.held_back_fit, 0);
}

TEST(LineLandmarks, RetirementFilterHoldsBackLinesPlacedLessCertainlyThanTheLimit) {
  // The slide's 8 views at the estimator's 1.5 px noise, the poses taken as exact.
  const double sigma = 1.5 / 458.0;
  LineViews views;
  for (int k = 0; k < 8; ++k) {
    LineView v;
    v.T_w_c = cameraAt(k);
    v.start_norm = projectNormalised(v.T_w_c, kP);
    v.end_norm = projectNormalised(v.T_w_c, kQ);
    views.push_back(v);
  }
  const LineUncertainty u =
      lineUncertainty(PluckerLine::fromPoints(kP, kQ), 0.5 * (kP + kQ), views, sigma);
  ASSERT_GT(u.midpoint_std_m, 1e-3);
  ASSERT_LT(u.midpoint_std_m, 0.5);
  LineRetirementFilter filter;
  filter.max_midpoint_std_m = 1.1 * u.midpoint_std_m;
  LineRetirementCounts counts;
  const std::vector<LineLandmark> retired = slideThrough(0, filter, 8, &counts);
  ASSERT_EQ(retired.size(), 1u);
  EXPECT_NEAR(retired[0].midpoint_std_m, u.midpoint_std_m, 1e-3 * u.midpoint_std_m);
  filter.max_midpoint_std_m = 0.9 * u.midpoint_std_m;
  EXPECT_TRUE(slideThrough(0, filter, 8, &counts).empty());
  EXPECT_EQ(counts.held_back_uncertain, 1);
  EXPECT_EQ(counts.retired + counts.held_back_fit + counts.held_back_parallax, 0);
}

TEST(LineLandmarks, ALandmarkRecreatedUnderARemovedIdStartsANewHistory) {
  // The tracker keeps a line's id after the estimator removed it as an outlier; the new
  // landmark's map fit must not include the views the old one had already passed on.
  LineLandmarks lines(3, LineTriangulationOptions{});
  const auto pose = [](int64_t ns) { return cameraAt(static_cast<int>(ns - 1000)); };
  for (int k = 0; k < 4; ++k) lines.addFrame(stamp(k), observeEdge(k));
  lines.triangulate(pose);
  for (int k = 0; k < 2; ++k) {
    const Eigen::Isometry3d T = cameraAt(k);
    lines.removeFrame(stamp(k), &T);  // two views into the history
  }
  lines.removeIds({3});
  for (int k = 4; k < 8; ++k) lines.addFrame(stamp(k), observeEdge(k));
  lines.triangulate(pose);
  for (int k = 4; k < 8; ++k) {
    const Eigen::Isometry3d T = cameraAt(k);
    lines.removeFrame(stamp(k), &T);
  }
  const std::vector<LineLandmark> retired = lines.takeRetired();
  ASSERT_EQ(retired.size(), 1u);
  EXPECT_EQ(retired[0].track_observations, 4);
}

TEST(LineLandmarks, RetirementSummaryNamesTheLimitsAndWarnsWhenMostTracksFailTheFit) {
  LineRetirementCounts c;
  c.retired = 43;
  c.held_back_fit = 73;
  c.held_back_parallax = 32;
  LineMapLimits limits;
  limits.max_rms_px = 0.5;
  limits.max_edge_rms_px = 0.35;
  limits.min_parallax = 0.1;
  EXPECT_EQ(describeLineRetirement(c, limits),
            "43 of 148 retired tracks; held back: 73 fit worse than 0.35 px RMS on their edges "
            "(0.5 px on the tracker's positions), 32 with cross parallax under 0.1");
  LineMapLimits no_edges = limits;  // lines.map_edges off
  no_edges.max_edge_rms_px = 0;
  EXPECT_EQ(describeLineRetirement(c, no_edges),
            "43 of 148 retired tracks; held back: 73 fit worse than 0.5 px RMS, 32 with cross "
            "parallax under 0.1");
  c.held_back_edge = 9;
  EXPECT_EQ(describeLineRetirement(c, limits),
            "43 of 157 retired tracks; held back: 73 fit worse than 0.35 px RMS on their edges "
            "(0.5 px on the tracker's positions), 32 with cross parallax under 0.1, 9 not found "
            "on their edge at full resolution");
  c.held_back_uncertain = 5;
  limits.max_midpoint_std_m = 0.03;
  EXPECT_EQ(describeLineRetirement(c, limits),
            "43 of 162 retired tracks; held back: 73 fit worse than 0.35 px RMS on their edges "
            "(0.5 px on the tracker's positions), 32 with cross parallax under 0.1, 9 not found "
            "on their edge at full resolution, 5 placed less certainly than 3 cm (1 sigma)");
  c.held_back_uncertain = 0;
  c.held_back_edge = 0;
  EXPECT_FALSE(fitLimitLooksTooTight(c));  // about half, as on the rendered benchmark
  c.held_back_fit = 300;                   // 300 of 375: 80 %
  EXPECT_TRUE(fitLimitLooksTooTight(c));
  // Too few tracks to judge (the first seconds after initialisation fit badly anyway).
  const LineRetirementCounts early{5, 46, 1};
  EXPECT_FALSE(fitLimitLooksTooTight(early));
  EXPECT_FALSE(fitLimitLooksTooTight(LineRetirementCounts{}));
}

namespace {
// Eight posed frames whose tracker positions lie on an edge 3 cm off the true one, and whose
// full-resolution edge positions (lines.map_edges) lie on the true edge in the first
// `on_edge` frames, `edge_noise_px` up and down in turn.
LineLandmark retireWithEdgePositions(int on_edge, const LineRetirementFilter& filter = {},
                                     double edge_noise_px = 0,
                                     LineRetirementCounts* counts = nullptr,
                                     bool checked_everywhere = false) {
  LineLandmarks lines(3, LineTriangulationOptions{});
  lines.setRetirementFilter(filter);
  for (int k = 0; k < 8; ++k) {
    auto obs = observeEdge(k, Eigen::Vector3d(0, 0, 0.03));
    obs[0].edge_checked = checked_everywhere || k < on_edge;
    if (k < on_edge) {
      const Eigen::Vector2d noise(0, (k % 2 ? 1 : -1) * edge_noise_px / 458.0);
      obs[0].on_edge = true;
      obs[0].edge_start_norm = projectNormalised(cameraAt(k), kP) + noise;
      obs[0].edge_end_norm = projectNormalised(cameraAt(k), kQ) + noise;
    }
    lines.addFrame(stamp(k), obs);
  }
  lines.triangulate([](int64_t ns) { return cameraAt(static_cast<int>(ns - 1000)); });
  for (int k = 0; k < 8; ++k) {
    const Eigen::Isometry3d T = cameraAt(k);
    lines.removeFrame(stamp(k), &T);
  }
  if (counts) *counts = lines.retirementCounts();
  const std::vector<LineLandmark> retired = lines.takeRetired();
  return retired.empty() ? LineLandmark() : retired[0];
}
}  // namespace

TEST(LineLandmarks, RetirementFitsTheEdgePositionsWhenHalfTheTrackHasThem) {
  const LineLandmark all = retireWithEdgePositions(8);
  EXPECT_EQ(all.track_observations, 8);
  EXPECT_LT(extentError(all), 1e-6);
  const LineLandmark half = retireWithEdgePositions(4);
  EXPECT_EQ(half.track_observations, 4);  // the four on the edge, the others left out
  EXPECT_LT(extentError(half), 1e-6);
  // Fewer than half: the tracker's positions, 3 cm off.
  const LineLandmark few = retireWithEdgePositions(3);
  EXPECT_EQ(few.track_observations, 8);
  EXPECT_NEAR(extentError(few), 0.03, 0.01);
}

TEST(LineLandmarks, TracksOnTheirEdgesMeetTheEdgeFitLimit) {
  LineRetirementFilter filter;
  filter.max_reprojection_rms = 0.2 / 458.0;
  filter.max_edge_reprojection_rms = 0.6 / 458.0;
  LineRetirementCounts counts;
  // Edge positions 0.4 px off in turn: within the edge limit, though not the other.
  EXPECT_EQ(retireWithEdgePositions(8, filter, 0.4, &counts).track_observations, 8);
  EXPECT_EQ(counts.retired, 1);
  filter.max_edge_reprojection_rms = 0.3 / 458.0;
  retireWithEdgePositions(8, filter, 0.4, &counts);
  EXPECT_EQ(counts.held_back_fit, 1);
  // A track fitted on the tracker's positions (too few on the edge) meets the other limit.
  filter.max_edge_reprojection_rms = 0;
  EXPECT_EQ(retireWithEdgePositions(3, filter, 0.4, &counts).track_observations, 8);
  EXPECT_EQ(counts.retired, 1);
}

TEST(LineLandmarks, TracksWhoseEdgeWasLookedForButRarelyFoundStayOutOfTheMap) {
  LineRetirementCounts counts;
  // The edge looked for on all eight frames, found on three: held back.
  EXPECT_EQ(retireWithEdgePositions(3, {}, 0, &counts, true).track_observations, 0);
  EXPECT_EQ(counts.held_back_edge, 1);
  EXPECT_EQ(counts.retired, 0);
  // Found on four of eight: fitted on those.
  EXPECT_EQ(retireWithEdgePositions(4, {}, 0, &counts, true).track_observations, 4);
  EXPECT_EQ(counts.retired, 1);
}

// lines.map_edges' positions as the estimator's observations (estimator.line_residuals_on_edges):
// the window's landmark and its triangulation take them, and a frame whose edge was looked for
// and not found is left out while the track goes on.
TEST(LineLandmarks, ResidualsOnEdgesTakeTheEdgePositionsAndSkipFramesWhereTheEdgeWasNotFound) {
  for (const bool on_edges : {false, true}) {
    LineLandmarks lines(3, LineTriangulationOptions{});
    lines.setResidualsOnEdges(on_edges);
    for (int k = 0; k < 8; ++k) {
      auto obs = observeEdge(k, Eigen::Vector3d(0, 0, 0.03));  // the tracker: 3 cm off
      obs[0].edge_checked = true;
      obs[0].on_edge = k != 2 && k != 5;
      if (obs[0].on_edge) {
        obs[0].edge_start_norm = projectNormalised(cameraAt(k), kP);
        obs[0].edge_end_norm = projectNormalised(cameraAt(k), kQ);
      }
      lines.addFrame(stamp(k), obs);
    }
    lines.triangulate([](int64_t ns) { return cameraAt(static_cast<int>(ns - 1000)); });
    const LineLandmark& l = lines.landmarks().at(3);
    ASSERT_TRUE(l.hasLine());
    EXPECT_EQ(l.observations.size(), on_edges ? 6u : 8u);
    EXPECT_EQ(l.observations.count(stamp(2)), on_edges ? 0u : 1u);
    // Distance of the true edge's endpoints from the triangulated line.
    double off = 0;
    for (const Eigen::Vector3d& x : {kP, kQ})
      off = std::max(off, (x - projectOntoLine(l.line_w, x)).norm());
    if (on_edges)
      EXPECT_LT(off, 1e-6);
    else
      EXPECT_NEAR(off, 0.03, 0.005);
  }
}

TEST(LineLandmarks, EndpointVelocitiesAreTheLinesMotionAcrossItself) {
  // A horizontal line moving down 0.01 per 50 ms while its detected ends slide along it: each
  // endpoint's velocity is the line's, 0.2 per second down, whatever the slide. The first
  // observation, which has no previous one, takes the second's.
  LineLandmarks lines(3, LineTriangulationOptions{});
  const auto frame = [](double y, double slide) {
    std::vector<LineObservation, Eigen::aligned_allocator<LineObservation>> obs(1);
    obs[0].id = 5;
    obs[0].start_norm = {-0.3 + slide, y};
    obs[0].end_norm = {0.2 - 2 * slide, y};
    return obs;
  };
  lines.addFrame(1'000'000'000, frame(0.10, 0.0));
  lines.addFrame(1'050'000'000, frame(0.11, 0.04));
  const auto& observations = lines.landmarks().at(5).observations;
  const LineLandmarkObservation& first = observations.begin()->second;
  const LineLandmarkObservation& second = observations.rbegin()->second;
  for (const Eigen::Vector2d& v :
       {first.start_velocity, first.end_velocity, second.start_velocity, second.end_velocity}) {
    EXPECT_NEAR(v.x(), 0.0, 1e-12);
    EXPECT_NEAR(v.y(), 0.2, 1e-9);
  }
}
