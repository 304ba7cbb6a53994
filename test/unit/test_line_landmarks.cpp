// The window's line landmarks: triangulation from window poses and retirement, where a line
// that left the window is refined over its history for the map.
#include <gtest/gtest.h>

#include <algorithm>

#include "alvio/estimator/line_landmarks.h"
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

std::vector<LineObservation, Eigen::aligned_allocator<LineObservation>> observeEdge(int k) {
  LineObservation o;
  o.id = 3;
  o.start_norm = projectNormalised(cameraAt(k), kP);
  o.end_norm = projectNormalised(cameraAt(k), kQ);
  return {o};
}

// Eight frames see the edge; the first `unposed` leave the window without a pose (as before
// initialisation), the rest with theirs. Returns what retired.
std::vector<LineLandmark> slideThrough(int unposed) {
  LineLandmarks lines(3, LineTriangulationOptions{});
  for (int k = 0; k < 8; ++k) lines.addFrame(stamp(k), observeEdge(k));
  lines.triangulate([](int64_t ns) { return cameraAt(static_cast<int>(ns - 1000)); });
  EXPECT_TRUE(lines.landmarks().at(3).hasLine());
  for (int k = 0; k < 8; ++k) {
    const Eigen::Isometry3d T = cameraAt(k);
    lines.removeFrame(stamp(k), k < unposed ? nullptr : &T);
  }
  EXPECT_TRUE(lines.landmarks().empty());
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
