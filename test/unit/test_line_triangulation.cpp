// Two-view and multi-view line triangulation, degeneracy checks, extents and the landmark.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "alvio/common/error.h"
#include "alvio/config/yaml_reader.h"
#include "alvio/geometry/line_landmark.h"
#include "alvio/geometry/line_projection_factor.h"
#include "alvio/geometry/line_quality.h"
#include "alvio/geometry/line_triangulation.h"
#include "alvio/geometry/orthonormal_line.h"
#include "line_test_utils.h"

using namespace alvio;
using alvio::test::lookAt;
using alvio::test::projectNormalised;

namespace {
constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

// A view of the part [a, b] (fractions along P->Q) of the segment, with pixel noise.
LineView observe(const Eigen::Isometry3d& T_w_c, const Eigen::Vector3d& P, const Eigen::Vector3d& Q,
                 double a, double b, double noise_norm, std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, noise_norm);
  LineView v;
  v.T_w_c = T_w_c;
  v.start_norm = projectNormalised(T_w_c, P + a * (Q - P)) + Eigen::Vector2d(g(rng), g(rng));
  v.end_norm = projectNormalised(T_w_c, P + b * (Q - P)) + Eigen::Vector2d(g(rng), g(rng));
  return v;
}

double residualCost(const LineViews& views, const PluckerLine& line_w) {
  double line[4], pose[7], cost = 0.0;
  OrthonormalLine::fromPlucker(line_w).toParameters(line);
  for (const LineView& v : views) {
    poseToParameters(v.T_w_c, pose);
    Eigen::Vector2d r;
    EXPECT_TRUE(LineProjectionFactor(v.start_norm, v.end_norm, Eigen::Isometry3d::Identity())
                    .residual(pose, line, &r));
    cost += r.squaredNorm();
  }
  return cost;
}

const Eigen::Vector3d kP(4.0, -1.0, 0.5), kQ(4.5, 1.5, 1.8);  // a 3 m edge ~4.5 m away
}  // namespace

TEST(LineTriangulation, TwoViewNoiseFreeIsExact) {
  std::mt19937 rng(21);
  for (int k = 0; k < 20; ++k) {
    const Eigen::Isometry3d Ta = lookAt(test::randomVector(rng, 0.5), kP + 0.5 * (kQ - kP));
    const Eigen::Isometry3d Tb =
        lookAt(Ta.translation() + test::randomVector(rng, 0.4), kP + 0.4 * (kQ - kP));
    // Different parts of the segment in each view: only the infinite line is shared.
    PluckerLine line;
    const auto status = triangulateLine(observe(Ta, kP, kQ, 0.1, 0.7, 0, rng),
                                        observe(Tb, kP, kQ, 0.3, 0.95, 0, rng), {}, &line);
    if (status == LineTriangulationStatus::kNearEpipole ||
        status == LineTriangulationStatus::kPlanesNearlyParallel)
      continue;  // a random baseline can be degenerate; that is tested below
    ASSERT_EQ(status, LineTriangulationStatus::kOk) << toString(status);
    EXPECT_TRUE(test::sameLine(line, PluckerLine::fromPoints(kP, kQ), 1e-8));
  }
}

TEST(LineTriangulation, RejectsBaselineAlongTheLine) {
  // Moving along the line keeps it in the epipolar plane: both planes are the same.
  std::mt19937 rng(22);
  const Eigen::Isometry3d Ta = lookAt({0, 0, 0}, kP);
  Eigen::Isometry3d Tb = Ta;
  Tb.translation() += 0.5 * (kQ - kP).normalized();
  PluckerLine line;
  const auto status = triangulateLine(observe(Ta, kP, kQ, 0.1, 0.7, 0, rng),
                                      observe(Tb, kP, kQ, 0.1, 0.7, 0, rng), {}, &line);
  EXPECT_TRUE(status == LineTriangulationStatus::kNearEpipole ||
              status == LineTriangulationStatus::kPlanesNearlyParallel)
      << toString(status);
}

TEST(LineTriangulation, RejectsTinyBaselineAndSmallPlaneAngle) {
  std::mt19937 rng(23);
  const Eigen::Isometry3d Ta = lookAt({0, 0, 0}, kP);
  Eigen::Isometry3d Tb = lookAt({0, 0, 0}, kQ);  // pure rotation
  PluckerLine line;
  EXPECT_EQ(triangulateLine(observe(Ta, kP, kQ, 0, 1, 0, rng), observe(Tb, kP, kQ, 0, 1, 0, rng),
                            {}, &line),
            LineTriangulationStatus::kBaselineTooSmall);
  // A 2 cm baseline sideways at 4.5 m: plane angle ~0.25 deg, below a 1 deg threshold but
  // fine for a 0.1 deg one.
  Tb = Ta;
  Tb.translation() += 0.02 * Ta.linear().col(0);
  LineTriangulationOptions options;
  options.min_epipole_angle_deg = 0.0;
  const LineView a = observe(Ta, kP, kQ, 0, 1, 0, rng), b = observe(Tb, kP, kQ, 0, 1, 0, rng);
  EXPECT_EQ(triangulateLine(a, b, options, &line), LineTriangulationStatus::kPlanesNearlyParallel);
  options.min_plane_angle_deg = 0.1;
  EXPECT_EQ(triangulateLine(a, b, options, &line), LineTriangulationStatus::kOk);
}

TEST(LineTriangulation, RejectsAnIntersectionBehindTheCameras) {
  // Two cameras looking along +z, 1 m apart in x; the "same" vertical line is seen at
  // x = 0.1 z from the first and at x - 1 = 0.3 z from the second: they meet at z = -5.
  Eigen::Isometry3d Ta = Eigen::Isometry3d::Identity(), Tb = Eigen::Isometry3d::Identity();
  Tb.translation() = Eigen::Vector3d(1, 0, 0);
  LineView a, b;
  a.T_w_c = Ta;
  a.start_norm = {0.1, -0.2};
  a.end_norm = {0.1, 0.2};
  b.T_w_c = Tb;
  b.start_norm = {0.3, -0.2};
  b.end_norm = {0.3, 0.2};
  PluckerLine line;
  EXPECT_EQ(triangulateLine(a, b, {}, &line), LineTriangulationStatus::kBehindCamera);
}

// Eight views moving across the line (it runs mostly along y and z, seen along x).
LineViews sweep(double noise, std::mt19937& rng) {
  LineViews views;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d position(0.05 * std::sin(i), 0.3 - 0.06 * i, -0.4 + 0.12 * i);
    views.push_back(observe(lookAt(position, kP + 0.5 * (kQ - kP)), kP, kQ, 0.05 * (i % 3),
                            1.0 - 0.04 * (i % 4), noise, rng));
  }
  return views;
}

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

TEST(LineTriangulation, MultiViewNoiseFreeIsExact) {
  std::mt19937 rng(30);
  PluckerLine line;
  ASSERT_EQ(triangulateLineMultiView(sweep(0.0, rng), {}, &line), LineTriangulationStatus::kOk);
  EXPECT_TRUE(test::sameLine(line, PluckerLine::fromPoints(kP, kQ), 1e-8));
}

TEST(LineTriangulation, MultiViewRefinementImprovesOnTheBestPair) {
  // 1 px endpoint noise, 0.8 m baseline at 4.5 m: the refined line is the least-squares one,
  // so it lowers the cost of every trial and the error on average.
  const double noise = 1.0 / 458.0;
  const PluckerLine truth = PluckerLine::fromPoints(kP, kQ);
  const Eigen::Vector3d mid = 0.5 * (kP + kQ);
  std::vector<double> seed_angle, refined_angle, seed_dist, refined_dist;
  for (int k = 0; k < 30; ++k) {
    std::mt19937 rng(100 + k);
    const LineViews views = sweep(noise, rng);
    LineTriangulationOptions no_refine;
    no_refine.refine_max_iterations = 0;
    PluckerLine seed, refined;
    ASSERT_EQ(triangulateLineMultiView(views, no_refine, &seed), LineTriangulationStatus::kOk);
    ASSERT_EQ(triangulateLineMultiView(views, {}, &refined), LineTriangulationStatus::kOk);
    EXPECT_LT(residualCost(views, refined), residualCost(views, seed));
    seed_angle.push_back(lineAngle(seed, truth) * kRadToDeg);
    refined_angle.push_back(lineAngle(refined, truth) * kRadToDeg);
    seed_dist.push_back(seed.distanceTo(mid));
    refined_dist.push_back(refined.distanceTo(mid));
  }
  auto mean = [](const std::vector<double>& v) {
    return std::accumulate(v.begin(), v.end(), 0.0) / v.size();
  };
  RecordProperty("median_angle_deg", std::to_string(median(refined_angle)));
  RecordProperty("median_midpoint_distance_m", std::to_string(median(refined_dist)));
  EXPECT_LT(median(refined_angle), 1.0);
  EXPECT_LT(median(refined_dist), 0.05);
  EXPECT_LT(mean(refined_angle), mean(seed_angle));
  EXPECT_LT(mean(refined_dist), mean(seed_dist));
}

TEST(LineTriangulation, MultiViewNeedsTwoViews) {
  LineViews views(1);
  PluckerLine line;
  EXPECT_EQ(triangulateLineMultiView(views, {}, &line), LineTriangulationStatus::kTooFewViews);
}

TEST(LineTriangulation, ExtentIsTheUnionOfTheObservedParts) {
  std::mt19937 rng(24);
  LineViews views = {observe(lookAt({0, -0.5, 0}, kP), kP, kQ, 0.2, 0.6, 0, rng),
                     observe(lookAt({0.2, 0.3, 0.1}, kQ), kP, kQ, 0.9, 0.4, 0, rng)};
  Eigen::Vector3d start, end;
  const PluckerLine truth = PluckerLine::fromPoints(kP, kQ);
  ASSERT_TRUE(lineExtent(truth, views, &start, &end));
  EXPECT_LT((start - (kP + 0.2 * (kQ - kP))).norm(), 1e-9);
  EXPECT_LT((end - (kP + 0.9 * (kQ - kP))).norm(), 1e-9);
}

TEST(LineTriangulation, ExtentSkipsEndpointsSeenAlongTheLine) {
  std::mt19937 rng(25);
  const Eigen::Vector3d u = (kQ - kP).normalized();
  const Eigen::Vector3d side = u.cross(Eigen::Vector3d::UnitZ()).normalized();
  // Seen almost end-on (rays within ~3 deg of the line), two pixels off: that endpoint's place
  // along the line is metres off.
  LineView along = observe(lookAt(kP - 3.0 * u + 0.15 * side, kP), kP, kQ, 0.0, 1.0, 0, rng);
  along.end_norm.x() += 2.0 / 460;
  const LineViews views = {observe(lookAt({0, -0.5, 0}, kP), kP, kQ, 0.2, 0.6, 0, rng), along};
  const PluckerLine truth = PluckerLine::fromPoints(kP, kQ);
  Eigen::Vector3d start, end;
  LineTriangulationOptions options;
  options.extent_min_ray_angle_deg = 0.0;
  ASSERT_TRUE(lineExtent(truth, views, &start, &end, options));
  EXPECT_GT((end - kQ).norm(), 0.5);  // the end-on view sets the extent, badly
  options.extent_min_ray_angle_deg = 10.0;
  ASSERT_TRUE(lineExtent(truth, views, &start, &end, options));
  EXPECT_LT((start - (kP + 0.2 * (kQ - kP))).norm(), 1e-9);
  EXPECT_LT((end - (kP + 0.6 * (kQ - kP))).norm(), 1e-9);
}

TEST(LineTriangulation, ExtentTrimLeavesOutTheViewsReachingFurthest) {
  std::mt19937 rng(26);
  const double parts[][2] = {{0.2, 0.6}, {0.25, 0.6}, {0.2, 0.55}, {0.3, 0.65}, {0.0, 1.0}};
  LineViews views;
  for (int i = 0; i < 5; ++i)
    views.push_back(observe(lookAt({0.1 * i, -0.5 + 0.2 * i, 0}, kP), kP, kQ, parts[i][0],
                            parts[i][1], 0, rng));
  const PluckerLine truth = PluckerLine::fromPoints(kP, kQ);
  auto fraction = [&](const Eigen::Vector3d& p) {
    return (p - kP).dot(kQ - kP) / (kQ - kP).squaredNorm();
  };
  Eigen::Vector3d start, end;
  LineTriangulationOptions options;
  options.extent_trim_fraction = 0.0;
  ASSERT_TRUE(lineExtent(truth, views, &start, &end, options));
  EXPECT_NEAR(std::min(fraction(start), fraction(end)), 0.0, 1e-9);
  EXPECT_NEAR(std::max(fraction(start), fraction(end)), 1.0, 1e-9);
  options.extent_trim_fraction = 0.2;  // one of five views at each end
  ASSERT_TRUE(lineExtent(truth, views, &start, &end, options));
  EXPECT_NEAR(std::min(fraction(start), fraction(end)), 0.2, 1e-9);
  EXPECT_NEAR(std::max(fraction(start), fraction(end)), 0.65, 1e-9);
}

TEST(LineLandmark, ExtentGrowsAndFollowsTheLine) {
  LineLandmark lm;
  lm.id = 7;
  EXPECT_FALSE(lm.hasLine());
  lm.setLine(PluckerLine::fromPoints({0, 0, 1}, {1, 0, 1}), LineLandmarkStatus::kTriangulated);
  EXPECT_TRUE(lm.hasLine());
  lm.unionExtent({0.2, 0.1, 1}, {0.5, 0, 1});  // off-line points are projected
  lm.unionExtent({0.4, 0, 1}, {-0.3, 0, 1});
  EXPECT_LT((lm.start_w - Eigen::Vector3d(-0.3, 0, 1)).norm(), 1e-12);
  EXPECT_LT((lm.end_w - Eigen::Vector3d(0.5, 0, 1)).norm(), 1e-12);
  // A refined line moves the extent onto it.
  lm.setLine(PluckerLine::fromPoints({0, 0, 1.1}, {1, 0, 1.1}), LineLandmarkStatus::kOptimised);
  EXPECT_NEAR(lm.start_w.z(), 1.1, 1e-12);
  EXPECT_NEAR(lm.end_w.x(), 0.5, 1e-12);
  EXPECT_STREQ(toString(lm.status), "optimised");
}

TEST(LineTriangulationOptions, LoadFromYamlAndNameBadKeys) {
  const auto yaml = YamlReader::fromString(
      "lines:\n  triangulation: {min_plane_angle_deg: 2.5, refine_huber_scale: 0.01}\n", "t.yaml");
  const auto o = LineTriangulationOptions::load(yaml, "lines.triangulation");
  EXPECT_DOUBLE_EQ(o.min_plane_angle_deg, 2.5);
  EXPECT_DOUBLE_EQ(o.refine_huber_scale, 0.01);
  EXPECT_DOUBLE_EQ(o.min_depth, LineTriangulationOptions().min_depth);
  const auto bad = YamlReader::fromString("tri: {min_baseline: -1}\n", "bad.yaml");
  try {
    LineTriangulationOptions::load(bad, "tri");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("tri.min_baseline"), std::string::npos) << e.what();
  }
}

// Line quality (line_quality.h): what keeps badly supported lines out of the maps.

TEST(LineQuality, ReprojectionRmsIsTheEndpointDistanceToTheProjectedLine) {
  const Eigen::Vector3d P(-1.0, 0.0, 4.0), Q(1.0, 0.0, 4.0);  // horizontal, 4 m ahead
  const PluckerLine line = PluckerLine::fromPoints(P, Q);
  LineViews views(2);
  views[1].T_w_c.translation() = Eigen::Vector3d(0.5, 0.0, 0.0);
  for (LineView& v : views) {
    v.start_norm = projectNormalised(v.T_w_c, P);
    v.end_norm = projectNormalised(v.T_w_c, Q);
  }
  EXPECT_LT(lineReprojectionRms(line, views), 1e-12);
  // One endpoint 0.01 off the (image x-axis) line: RMS over the four distances is 0.005.
  views[1].end_norm.y() += 0.01;
  double start = 0, end = 0;
  ASSERT_TRUE(lineEndpointDistances(line, views[1], &start, &end));
  EXPECT_NEAR(start, 0.0, 1e-12);
  EXPECT_NEAR(end, 0.01, 1e-12);
  EXPECT_NEAR(lineReprojectionRms(line, views), 0.005, 1e-12);
  // Seen end-on, the line has no image line: never a good fit.
  LineView end_on;
  end_on.T_w_c = lookAt({-3.0, 0.0, 4.0}, P);
  EXPECT_FALSE(lineEndpointDistances(line, end_on, &start, &end));
  views.push_back(end_on);
  EXPECT_TRUE(std::isinf(lineReprojectionRms(line, views)));
}

TEST(LineQuality, CrossParallaxCountsOnlyMotionAcrossTheLine) {
  const Eigen::Vector3d P(-1.0, 0.0, 4.0), Q(1.0, 0.0, 4.0);  // along x, 4 m ahead
  const auto viewsFrom = [](const std::vector<Eigen::Vector3d>& centres) {
    LineViews views(centres.size());
    for (std::size_t k = 0; k < centres.size(); ++k) views[k].T_w_c.translation() = centres[k];
    return views;
  };
  // 1 m along the line, or towards it: the line's plane does not turn.
  EXPECT_NEAR(lineCrossParallax(P, Q, viewsFrom({{0, 0, 0}, {1, 0, 0}})), 0.0, 1e-12);
  EXPECT_NEAR(lineCrossParallax(P, Q, viewsFrom({{0, 0, 0}, {0, 0, 1}})), 0.0, 1e-12);
  // 0.4 m across it (y), at a median distance of 4 m: about 0.1.
  const double across = lineCrossParallax(P, Q, viewsFrom({{0, 0, 0}, {0, 0.2, 0}, {0, 0.4, 0}}));
  EXPECT_NEAR(across, 0.1, 1e-3);
  // A single view has no parallax.
  EXPECT_EQ(lineCrossParallax(P, Q, viewsFrom({{0, 0, 0}})), 0.0);
}

TEST(LineQuality, UncertaintyPredictsTheSpreadOfRefinedLines) {
  // Monte Carlo: the spread of lines refined from noisy views matches the predicted 1-sigma
  // uncertainty of the direction and of the midpoint's position across the line.
  const double noise = 1.0 / 458.0;
  const PluckerLine truth = PluckerLine::fromPoints(kP, kQ);
  const Eigen::Vector3d mid = 0.5 * (kP + kQ);
  std::mt19937 clean(7);
  const LineUncertainty predicted = lineUncertainty(truth, mid, sweep(0.0, clean), noise);
  double angle2 = 0, distance2 = 0;
  const int trials = 300;
  for (int k = 0; k < trials; ++k) {
    std::mt19937 rng(500 + k);
    PluckerLine line;
    ASSERT_EQ(triangulateLineMultiView(sweep(noise, rng), {}, &line), LineTriangulationStatus::kOk);
    angle2 += std::pow(lineAngle(line, truth) * kRadToDeg, 2);
    distance2 += std::pow(line.distanceTo(mid), 2);
  }
  const double angle_rms = std::sqrt(angle2 / trials);
  const double distance_rms = std::sqrt(distance2 / trials);
  RecordProperty("predicted_midpoint_std_m", std::to_string(predicted.midpoint_std_m));
  RecordProperty("measured_midpoint_rms_m", std::to_string(distance_rms));
  EXPECT_NEAR(distance_rms / predicted.midpoint_std_m, 1.0, 0.15);
  EXPECT_NEAR(angle_rms / predicted.direction_std_deg, 1.0, 0.15);
}

TEST(LineQuality, MidpointUncertaintyGrowsWithDepthAndFallsWithBaseline) {
  std::mt19937 rng(8);
  const double noise = 1.0 / 458.0;
  const auto stdAt = [&](double depth_scale, double baseline_scale) {
    // The whole scene scaled about the first camera, the camera path scaled on its own.
    const Eigen::Vector3d P = depth_scale * kP, Q = depth_scale * kQ;
    LineViews views;
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector3d position =
          baseline_scale * Eigen::Vector3d(0.05 * std::sin(i), 0.3 - 0.06 * i, -0.4 + 0.12 * i);
      views.push_back(observe(lookAt(position, 0.5 * (P + Q)), P, Q, 0, 1, 0, rng));
    }
    return lineUncertainty(PluckerLine::fromPoints(P, Q), 0.5 * (P + Q), views, noise)
        .midpoint_std_m;
  };
  const double base = stdAt(1, 1);
  EXPECT_GT(stdAt(2, 1), 2 * base);  // depth error grows with the square of the distance
  EXPECT_LT(stdAt(1, 2), 0.6 * base);
  // Views all from one place: the depth is unobservable.
  EXPECT_GT(stdAt(1, 1e-6), 1e3 * base);
}

TEST(LineQuality, UncertaintyScalesWithTheLineNoise) {
  // The map limits (estimator.line_map_max_midpoint_std_m, mapping.max_line_direction_std_deg)
  // were tuned at one line_map_sigma_px; they carry to another by the same factor only if the
  // standard deviations follow the noise to rounding (and to the last bit for a power of two).
  std::mt19937 rng(3);
  LineViews views;
  for (int i = 0; i < 6; ++i) {
    const Eigen::Vector3d position(0.04 * i, 0.3 - 0.05 * i, -0.4 + 0.1 * i);
    views.push_back(observe(lookAt(position, 0.5 * (kP + kQ)), kP, kQ, 0, 1, 0, rng));
  }
  const PluckerLine line = PluckerLine::fromPoints(kP, kQ);
  const Eigen::Vector3d mid = 0.5 * (kP + kQ);
  const double f = 458.654;
  const LineUncertainty tuned = lineUncertainty(line, mid, views, 1.5 / f);
  ASSERT_GT(tuned.midpoint_std_m, 0);
  const LineUncertainty half = lineUncertainty(line, mid, views, 0.75 / f);
  EXPECT_EQ(half.midpoint_std_m, 0.5 * tuned.midpoint_std_m);
  EXPECT_EQ(half.direction_std_deg, 0.5 * tuned.direction_std_deg);
  const LineUncertainty third = lineUncertainty(line, mid, views, 0.5 / f);
  EXPECT_NEAR(third.midpoint_std_m, tuned.midpoint_std_m / 3, 1e-12 * tuned.midpoint_std_m);
  EXPECT_NEAR(third.direction_std_deg, tuned.direction_std_deg / 3,
              1e-12 * tuned.direction_std_deg);
  EXPECT_NEAR(lineDirectionStdDeg(line, views, 0.5 / f), tuned.direction_std_deg / 3,
              1e-12 * tuned.direction_std_deg);
}
