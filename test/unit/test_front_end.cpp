// The front end: lines tracked in their own thread give exactly the frames of the one-thread
// front end.
#include <gtest/gtest.h>

#include "alvio/config/config.h"
#include "alvio/pipeline/front_end.h"
#include "synthetic_line_scene.h"
#include "test_support.h"

using namespace alvio;

TEST(FrontEnd, LinesInTheirOwnThreadGiveTheSameFrames) {
  Config config = Config::load(test::sourcePath("config/euroc.yaml"));
  config.estimator.use_lines = true;
  const cv::Size size(config.camera.width, config.camera.height);
  const test::SyntheticLineScene scene(size);
  const std::vector<test::Bar> bars = {
      {{200, 150}, {220, 40}, 0}, {{520, 140}, {180, 36}, 60}, {{250, 350}, {260, 44}, -20}};
  Config threaded = config;
  threaded.lines.own_thread = true;
  config.lines.own_thread = false;
  FrontEnd one(config), two(threaded);
  std::size_t lines_seen = 0;
  for (int k = 0; k < 6; ++k) {
    const cv::Mat image = scene.render(bars, {1.5 * k, 0.8 * k});
    const int64_t t_ns = 1'000'000'000 + k * 50'000'000LL;
    const FeatureFrame a = one.track(image, t_ns), b = two.track(image, t_ns);
    ASSERT_EQ(a.points.size(), b.points.size()) << "frame " << k;
    for (std::size_t i = 0; i < a.points.size(); ++i) {
      EXPECT_EQ(a.points[i].id, b.points[i].id);
      EXPECT_EQ(a.points[i].px, b.points[i].px);
    }
    ASSERT_EQ(a.lines.size(), b.lines.size()) << "frame " << k;
    for (std::size_t i = 0; i < a.lines.size(); ++i) {
      EXPECT_EQ(a.lines[i].id, b.lines[i].id);
      EXPECT_EQ(a.lines[i].start_px, b.lines[i].start_px);
      EXPECT_EQ(a.lines[i].end_px, b.lines[i].end_px);
    }
    lines_seen += b.lines.size();
  }
  EXPECT_GE(lines_seen, 6u * 6u) << "the bars' edges are tracked";
}
