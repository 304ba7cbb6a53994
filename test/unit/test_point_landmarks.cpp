// The window's point landmarks: the keyframe decision (VINS-Mono's parallax test).
#include <gtest/gtest.h>

#include "alvio/estimator/point_landmarks.h"

using namespace alvio;

namespace {

constexpr double kMinParallax = 0.02;  // normalised; about 9 px at EuRoC's focal length

// `n` points with consecutive IDs from `first_id`, spread along x and moved by `shift`.
FeatureFrame pointsAt(int first_id, int n, double shift) {
  FeatureFrame f;
  for (int i = 0; i < n; ++i) {
    PointObservation o;
    o.id = first_id + i;
    o.xy = Eigen::Vector2d(0.01 * i + shift, 0.005 * i);
    f.points.push_back(o);
  }
  return f;
}

// Frame 2's decision: it weighs how far the points moved from frame 0 to frame 1.
bool thirdFrameIsKeyframe(PointLandmarks& landmarks, double motion, const FeatureFrame& third) {
  landmarks.addFrameAndCheckParallax(0, pointsAt(0, 30, 0.0));
  landmarks.addFrameAndCheckParallax(1, pointsAt(0, 30, motion));
  return landmarks.addFrameAndCheckParallax(2, third);
}

}  // namespace

TEST(PointLandmarks, AFrameIsAKeyframeOncePointsMovedEnoughBetweenTheTwoFramesBeforeIt) {
  PointLandmarks slow(10, kMinParallax), fast(10, kMinParallax);
  EXPECT_FALSE(thirdFrameIsKeyframe(slow, 0.015, pointsAt(0, 30, 0.015)));
  EXPECT_TRUE(thirdFrameIsKeyframe(fast, 0.025, pointsAt(0, 30, 0.025)));
  EXPECT_EQ(fast.lastTrackedCount(), 30);
}

TEST(PointLandmarks, AFrameWithFewerThanTwentyTrackedPointsIsAKeyframe) {
  PointLandmarks landmarks(10, kMinParallax);
  EXPECT_TRUE(thirdFrameIsKeyframe(landmarks, 0.0, pointsAt(0, 19, 0.0)));
  EXPECT_EQ(landmarks.lastTrackedCount(), 19);
}

namespace {

// A landmark seen by cameras translating along x (identity rotations, camera = body) in
// frames 0..n-1, with the true point `p` in the world (= frame 0's camera).
PointLandmark landmarkSeenAlongALine(const Eigen::Vector3d& p, int n,
                                     std::vector<Eigen::Vector3d>* P,
                                     std::vector<Eigen::Matrix3d>* R) {
  PointLandmark l;
  for (int i = 0; i < n; ++i) {
    P->push_back(Eigen::Vector3d(0.1 * i, 0, 0));
    R->push_back(Eigen::Matrix3d::Identity());
    const Eigen::Vector3d c = p - P->back();
    PointSighting s;
    s.xy1 = c / c.z();
    l.sightings.push_back(s);
  }
  return l;
}

}  // namespace

TEST(PointLandmarks, RetriangulateRefreshesOnlyTheNamedLandmarksDepths) {
  std::vector<Eigen::Vector3d> P;
  std::vector<Eigen::Matrix3d> R;
  const PointLandmark seen = landmarkSeenAlongALine(Eigen::Vector3d(0.3, -0.2, 4.0), 5, &P, &R);
  PointLandmarks landmarks(10, kMinParallax);
  for (int id : {1, 2}) {
    PointLandmark l = seen;
    l.id = id;
    l.depth = 9.0;  // stale
    landmarks.landmarks().emplace(id, l);
  }
  landmarks.retriangulate(P, R, Eigen::Isometry3d::Identity(),
                          [](const PointLandmark& l) { return l.id == 2; });
  EXPECT_DOUBLE_EQ(landmarks.landmarks().at(1).depth, 9.0);
  EXPECT_NEAR(landmarks.landmarks().at(2).depth, 4.0, 1e-9);
}

TEST(PointLandmarks, RetriangulateKeepsTheDepthWhenTheSightingsDoNotPlaceThePoint) {
  std::vector<Eigen::Vector3d> P;
  std::vector<Eigen::Matrix3d> R;
  // All cameras at one place: no parallax, the depth is not observable.
  PointLandmark l = landmarkSeenAlongALine(Eigen::Vector3d(0.3, -0.2, 4.0), 5, &P, &R);
  for (auto& p : P) p.setZero();
  for (auto& s : l.sightings) s.xy1 = Eigen::Vector3d(0.3 / 4, -0.2 / 4, 1);
  l.id = 1;
  l.depth = 3.0;
  PointLandmarks landmarks(10, kMinParallax);
  landmarks.landmarks().emplace(1, l);
  landmarks.retriangulate(P, R, Eigen::Isometry3d::Identity(),
                          [](const PointLandmark&) { return true; });
  EXPECT_DOUBLE_EQ(landmarks.landmarks().at(1).depth, 3.0);
}
