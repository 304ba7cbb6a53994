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
