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

// The depth of `l`, started at `depth`, after retriangulate at the poses P, R.
double depthAfterRetriangulation(PointLandmark l, double depth,
                                 const std::vector<Eigen::Vector3d>& P,
                                 const std::vector<Eigen::Matrix3d>& R) {
  l.id = 1;
  l.depth = depth;
  PointLandmarks landmarks(10, kMinParallax);
  landmarks.landmarks().emplace(1, l);
  landmarks.retriangulate(P, R, Eigen::Isometry3d::Identity(),
                          [](const PointLandmark&) { return true; });
  return landmarks.landmarks().at(1).depth;
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
  EXPECT_DOUBLE_EQ(depthAfterRetriangulation(l, 3.0, P, R), 3.0);
}

TEST(PointLandmarks, RetriangulateKeepsTheDepthWhenTheSightingsPlaceThePointBehindTheCamera) {
  std::vector<Eigen::Vector3d> P;
  std::vector<Eigen::Matrix3d> R;
  const PointLandmark l = landmarkSeenAlongALine(Eigen::Vector3d(0.3, -0.2, -4.0), 5, &P, &R);
  EXPECT_DOUBLE_EQ(depthAfterRetriangulation(l, 3.0, P, R), 3.0);
}

// Landmarks first seen in different frames share the window's poses: each is placed from its
// own first camera, whatever the others' (rotating body, camera offset from the body).
TEST(PointLandmarks, EveryLandmarkIsTriangulatedFromItsOwnFirstCamera) {
  Eigen::Isometry3d T_b_c = Eigen::Isometry3d::Identity();
  T_b_c.linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d(0.3, 1, 0).normalized()).matrix();
  T_b_c.translation() = Eigen::Vector3d(0.05, -0.02, 0.01);
  std::vector<Eigen::Vector3d> P;
  std::vector<Eigen::Matrix3d> R;
  for (int i = 0; i < 6; ++i) {
    P.emplace_back(0.12 * i, 0.03 * i * i, -0.02 * i);
    R.push_back(Eigen::AngleAxisd(0.05 * i, Eigen::Vector3d::UnitZ()).matrix() *
                Eigen::AngleAxisd(-0.03 * i, Eigen::Vector3d::UnitX()).matrix());
  }
  auto inCamera = [&](int i, const Eigen::Vector3d& p_w) -> Eigen::Vector3d {
    const Eigen::Matrix3d R_w_c = R[i] * T_b_c.linear();
    return R_w_c.transpose() * (p_w - (P[i] + R[i] * T_b_c.translation()));
  };
  struct Truth {
    int start, end;
    Eigen::Vector3d p_w;
  };
  const std::vector<Truth> truths = {{0, 5, {0.4, 0.3, 5.0}},
                                     {1, 4, {-0.6, 0.1, 3.5}},
                                     {2, 5, {0.2, -0.5, 6.0}},
                                     {3, 5, {1.0, 0.4, 4.2}}};
  PointLandmarks landmarks(10, kMinParallax);
  for (std::size_t id = 0; id < truths.size(); ++id) {
    PointLandmark l;
    l.id = static_cast<int>(id);
    l.start_frame = truths[id].start;
    for (int i = truths[id].start; i <= truths[id].end; ++i) {
      const Eigen::Vector3d c = inCamera(i, truths[id].p_w);
      PointSighting s;
      s.xy1 = c / c.z();
      l.sightings.push_back(s);
    }
    landmarks.landmarks().emplace(l.id, l);
  }
  auto expectTrueDepths = [&](const char* after) {
    for (std::size_t id = 0; id < truths.size(); ++id)
      EXPECT_NEAR(landmarks.landmarks().at(static_cast<int>(id)).depth,
                  inCamera(truths[id].start, truths[id].p_w).z(), 1e-9)
          << "landmark " << id << " after " << after;
  };
  landmarks.triangulate(P, R, T_b_c);
  expectTrueDepths("triangulate");
  for (auto& [id, l] : landmarks.landmarks()) l.depth = 9.0;  // stale
  landmarks.retriangulate(P, R, T_b_c, [](const PointLandmark&) { return true; });
  expectTrueDepths("retriangulate");
}

TEST(PointLandmarks, ANewTracksFirstSightingTakesTheVelocityOfItsSecond) {
  // The front end knows no velocity for a point in its first frame; the time shift's estimate
  // needs one for every sighting, the anchor above all.
  PointLandmarks landmarks(10, kMinParallax);
  FeatureFrame first = pointsAt(0, 2, 0.0), second = pointsAt(0, 2, 0.01);
  for (PointObservation& o : second.points) o.velocity = {0.2, -0.1};
  second.points[1].velocity = Eigen::Vector2d::Zero();  // a still point stays still
  landmarks.addFrameAndCheckParallax(0, first);
  landmarks.addFrameAndCheckParallax(1, second);
  const PointLandmark& moving = landmarks.landmarks().at(0);
  EXPECT_EQ(moving.sightings[0].velocity, Eigen::Vector2d(0.2, -0.1));
  EXPECT_EQ(moving.sightings[1].velocity, Eigen::Vector2d(0.2, -0.1));
  EXPECT_EQ(landmarks.landmarks().at(1).sightings[0].velocity, Eigen::Vector2d::Zero());
}
