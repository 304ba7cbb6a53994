// The point tracker's corner detection schedule (points.detect_every).
#include <gtest/gtest.h>

#include <set>

#include "alvio/camera/camera_model.h"
#include "alvio/common/error.h"
#include "alvio/config/yaml_reader.h"
#include "alvio/frontend/point_tracker.h"
#include "synthetic_line_scene.h"

using namespace alvio;

namespace {
const cv::Size kSize(752, 480);
const std::vector<test::Bar> kBars = {{{200, 150}, {220, 40}, 0}, {{520, 140}, {180, 36}, 60}};

std::set<int> idsOf(const FeatureFrame& f) {
  std::set<int> ids;
  for (const auto& p : f.points) ids.insert(p.id);
  return ids;
}

int newIds(const FeatureFrame& f, const std::set<int>& known) {
  int n = 0;
  for (const auto& p : f.points) n += known.count(p.id) == 0;
  return n;
}
}  // namespace

TEST(PointTracker, DetectEveryOtherFrameAddsCornersOnlyOnDetectionFrames) {
  const test::SyntheticLineScene scene(kSize);
  std::shared_ptr<const CameraModel> camera = CameraModel::create(test::undistortedCamera());
  // The scene slides left, so corners leave the image and detection has room to add some.
  const cv::Mat f1 = scene.render(kBars, {0, 0}), f2 = scene.render(kBars, {-24, 0}),
                f3 = scene.render(kBars, {-48, 0});

  PointTrackerOptions every_frame;
  PointTracker reference(every_frame, camera);
  const std::set<int> first = idsOf(reference.track(f1, 0));
  ASSERT_GE(first.size(), 50u);
  EXPECT_GT(newIds(reference.track(f2, 50'000'000), first), 0) << "the default detects each frame";

  PointTrackerOptions every_other = every_frame;
  every_other.detect_every = 2;
  PointTracker tracker(every_other, camera);
  EXPECT_EQ(idsOf(tracker.track(f1, 0)), first);
  const FeatureFrame second = tracker.track(f2, 50'000'000);
  EXPECT_EQ(newIds(second, first), 0);
  EXPECT_LT(second.points.size(), first.size()) << "corners left the image";
  EXPECT_GT(newIds(tracker.track(f3, 100'000'000), first), 0);
}

TEST(PointTrackerOptions, DetectEveryMustBePositive) {
  const auto yaml = YamlReader::fromString("points:\n  detect_every: 0\n", "p.yaml");
  try {
    PointTrackerOptions::load(yaml, "points");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("points.detect_every"), std::string::npos) << e.what();
  }
  const auto ok = YamlReader::fromString("points:\n  detect_every: 3\n", "p.yaml");
  EXPECT_EQ(PointTrackerOptions::load(ok, "points").detect_every, 3);
}
