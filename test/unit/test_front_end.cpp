// The front end: lines tracked in their own thread give exactly the frames of the one-thread
// front end; the point tracker looks for new corners only once enough are missing.
#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "alvio/camera/camera_model.h"
#include "alvio/config/config.h"
#include "alvio/frontend/point_tracker.h"
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

TEST(PointTracker, NewCornersWaitUntilEnoughAreMissing) {
  const Config config = Config::load(test::sourcePath("config/euroc.yaml"));
  const std::shared_ptr<const CameraModel> camera = CameraModel::create(config.camera);
  const int w = config.camera.width, h = config.camera.height;
  // A wide texture seen through a window that slides left: the content moves right and
  // corners leave the image on the right, a known few a frame.
  cv::Mat texture(h, w + 400, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 3.0);
  cv::normalize(texture, texture, 0, 255, cv::NORM_MINMAX);
  const auto view = [&](int shift) { return texture(cv::Rect(400 - shift, 0, w, h)).clone(); };
  const auto maxId = [](const FeatureFrame& f) {
    int m = -1;
    for (const PointObservation& o : f.points) m = std::max(m, o.id);
    return m;
  };
  for (const int min_new : {1, 20}) {
    SCOPED_TRACE("min_new_features " + std::to_string(min_new));
    PointTrackerOptions options = config.points;
    options.min_new_features = min_new;
    PointTracker tracker(options, camera);
    const FeatureFrame first = tracker.track(view(0), 0);
    ASSERT_EQ(static_cast<int>(first.points.size()), options.max_features);
    int last_id = maxId(first), small_gaps = 0, large_gaps = 0;
    int64_t t_ns = 0;
    for (const int shift : {6, 12, 18, 24, 90, 96}) {
      t_ns += 50'000'000;
      const FeatureFrame f = tracker.track(view(shift), t_ns);
      int tracked = 0;  // points of earlier frames
      for (const PointObservation& o : f.points) tracked += o.id <= last_id;
      const int missing = options.max_features - tracked;
      const bool searched = maxId(f) > last_id;
      if (missing >= min_new) {
        EXPECT_TRUE(searched) << missing << " missing after shift " << shift;
        ++large_gaps;
      } else {
        EXPECT_FALSE(searched) << "only " << missing << " missing after shift " << shift;
        EXPECT_EQ(static_cast<int>(f.points.size()), tracked);
        ++small_gaps;
      }
      last_id = std::max(last_id, maxId(f));
    }
    // The slide exercises both rules: a few lost a frame, then a jump that loses many.
    EXPECT_GE(large_gaps, 1);
    if (min_new > 1) {
      EXPECT_GE(small_gaps, 1);
    }
  }
}
