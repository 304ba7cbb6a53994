// The front end: lines tracked in their own thread give exactly the frames of the one-thread
// front end, and corrupted gyroscope samples leave the tracks as clean ones do; the point tracker
// looks for new corners only once enough are missing, and tracks back only the corners whose
// anchored patch did not align when asked to, and ends tracks whose patch stopped matching before
// initialisation only when configured to.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <map>
#include <opencv2/imgproc.hpp>

#include "alvio/camera/camera_model.h"
#include "alvio/config/config.h"
#include "alvio/frontend/point_tracker.h"
#include "alvio/pipeline/front_end.h"
#include "synthetic_line_scene.h"
#include "test_images.h"
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

TEST(FrontEnd, CorruptedGyroscopeSamplesLeaveTheTracksAsCleanOnesDo) {
  // The faults suite's corrupted IMU: one sample in three NaN or infinite. With the
  // gyroscope's flow on, such a sample used to make every predicted corner NaN.
  Config config = Config::load(test::sourcePath("config/euroc.yaml"));
  config.estimator.use_lines = false;
  ASSERT_TRUE(config.points.gyro_flow);
  const int w = config.camera.width, h = config.camera.height;
  const cv::Mat texture = test::stretched(test::blurredNoise(cv::Size(w + 100, h), 7, 3.0));
  const auto view = [&](int shift) { return texture(cv::Rect(100 - shift, 0, w, h)).clone(); };
  FrontEnd clean(config), corrupted(config);
  const int64_t imu_dt = 5'000'000, frame_dt = 50'000'000;
  int64_t t_imu = 0;
  std::size_t kept = 0;
  for (int k = 0; k < 6; ++k) {
    const int64_t t_ns = k * frame_dt;
    for (; t_imu <= t_ns + imu_dt; t_imu += imu_dt) {  // up to one sample beyond the image
      ImuSample s;
      s.t_ns = t_imu;
      s.acc = Eigen::Vector3d(0, 0, 9.81);
      s.gyr = Eigen::Vector3d(0.02, -0.01, 0.03);
      clean.addImu(s);
      if ((t_imu / imu_dt) % 3 == 1)
        s.gyr.x() = (t_imu / imu_dt) % 2 ? std::numeric_limits<double>::quiet_NaN()
                                         : std::numeric_limits<double>::infinity();
      corrupted.addImu(s);
    }
    const FeatureFrame a = clean.track(view(2 * k), t_ns), b = corrupted.track(view(2 * k), t_ns);
    ASSERT_EQ(a.points.size(), b.points.size()) << "frame " << k;
    for (std::size_t i = 0; i < a.points.size(); ++i) {
      EXPECT_EQ(a.points[i].id, b.points[i].id);
      EXPECT_NEAR((a.points[i].px - b.points[i].px).norm(), 0.0, 1e-6);
    }
    kept = b.points.size();
  }
  EXPECT_GE(kept, 100u) << "the corners are tracked through all six frames";
}

TEST(PointTracker, NewCornersWaitUntilEnoughAreMissing) {
  const Config config = Config::load(test::sourcePath("config/euroc.yaml"));
  const std::shared_ptr<const CameraModel> camera = CameraModel::create(config.camera);
  const int w = config.camera.width, h = config.camera.height;
  // A wide texture seen through a window that slides left: the content moves right and
  // corners leave the image on the right, a known few a frame.
  const cv::Mat texture = test::stretched(test::blurredNoise(cv::Size(w + 400, h), 7, 3.0));
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

TEST(PointTracker, AlignedCornersSkipTheBackwardCheckAndOccludedOnesStillEnd) {
  const Config config = Config::load(test::sourcePath("config/euroc.yaml"));
  const std::shared_ptr<const CameraModel> camera = CameraModel::create(config.camera);
  const int w = config.camera.width, h = config.camera.height;
  const cv::Mat texture = test::stretched(test::blurredNoise(cv::Size(w + 400, h), 11, 3.0));
  const cv::Mat other = test::stretched(test::blurredNoise(cv::Size(w, h), 12, 3.0));
  // The content slides right by `shift` pixels.
  const auto view = [&](int shift) { return texture(cv::Rect(400 - shift, 0, w, h)).clone(); };
  // In the last frame an unrelated surface covers the image's left third.
  const cv::Rect occluder(0, 0, w / 3, h);
  const std::vector<int> shifts = {0, 3, 6, 9, 12, 15};
  for (const bool skip : {false, true}) {
    SCOPED_TRACE(skip ? "skipping the aligned corners' backward check" : "checking all corners");
    PointTrackerOptions options = config.points;
    options.gyro_flow = false;
    options.anchors.enabled = true;
    options.anchors.skip_backward_when_aligned = skip;
    PointTracker tracker(options, camera);
    std::map<int, Eigen::Vector2d> first;  // each corner's position where it was found
    std::map<int, int> found_at;           // and the shift then
    for (std::size_t f = 0; f < shifts.size(); ++f) {
      cv::Mat image = view(shifts[f]);
      const bool occluded = f + 1 == shifts.size();
      if (occluded) other(occluder).copyTo(image(occluder));
      const FeatureFrame frame = tracker.track(image, static_cast<int64_t>(f) * 50'000'000);
      std::size_t old_tracks = 0, in_occluder = 0;
      std::vector<double> errors;
      for (const PointObservation& o : frame.points) {
        if (!first.count(o.id)) {
          first[o.id] = o.px;
          found_at[o.id] = shifts[f];
          continue;
        }
        ++old_tracks;
        const Eigen::Vector2d truth =
            first[o.id] + Eigen::Vector2d(shifts[f] - found_at[o.id], 0.0);
        if (occluded && occluder.contains(cv::Point(cvRound(truth.x()), cvRound(truth.y())))) {
          ++in_occluder;
          continue;
        }
        // A patch the occluder's edge cuts into may still align, about a pixel off.
        if (occluded && truth.x() < occluder.br().x + options.klt_window / 2 + 1) continue;
        const double error = (o.px - truth).norm();
        // A wrong arrival lands pixels away; near the border, where no patch fits, KLT alone
        // errs by tenths of a pixel.
        EXPECT_LT(error, 1.0) << "corner " << o.id << " in frame " << f;
        errors.push_back(error);
      }
      if (f == 0) continue;
      ASSERT_GT(old_tracks, occluded ? 50u : 100u);
      // No corner whose surface the occluder hides goes on, checked back or not.
      if (occluded) {
        EXPECT_EQ(in_occluder, 0u);
      }
      std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
      EXPECT_LT(errors[errors.size() / 2], 0.05) << "median error in frame " << f;
      if (!skip) {
        EXPECT_GE(tracker.lastBackwardChecks(), old_tracks);
      } else if (!occluded) {
        EXPECT_LE(tracker.lastBackwardChecks(), old_tracks / 10)
            << "corners whose patch aligned are not tracked back";
      }
    }
  }
}

// A surface whose look changes slowly (here: cross-faded into another texture while it
// slides) keeps its corners frame to frame, but their first patches stop matching. The
// anchors end such tracks once the estimator tracks; before it has initialised they may go
// on (end_mismatched_before_init: false), because its structure from motion needs points
// shared across the whole window.
TEST(PointTracker, MismatchedPatchesEndTracksBeforeInitialisationOnlyWhenConfigured) {
  const Config config = Config::load(test::sourcePath("config/euroc.yaml"));
  const std::shared_ptr<const CameraModel> camera = CameraModel::create(config.camera);
  const int w = config.camera.width, h = config.camera.height;
  const cv::Mat a = test::stretched(test::blurredNoise(cv::Size(w + 100, h), 21, 3.0));
  const cv::Mat b = test::stretched(test::blurredNoise(cv::Size(w + 100, h), 22, 3.0));
  const int frames = 12;
  // The content slides right 2 px a frame while b's share grows by 8 % a frame.
  const auto view = [&](int k) {
    const cv::Rect r(100 - 2 * k, 0, w, h);
    cv::Mat out;
    cv::addWeighted(a(r), 1.0 - 0.08 * k, b(r), 0.08 * k, 0.0, out);
    return out;
  };
  // How many of the first frame's corners the last frame still tracks.
  const auto survivors = [&](bool end_before_init, bool estimator_tracking) {
    PointTrackerOptions options = config.points;
    options.anchors.enabled = true;
    options.anchors.end_mismatched = true;
    options.anchors.end_mismatched_before_init = end_before_init;
    PointTracker tracker(options, camera);
    tracker.setEstimatorTracking(estimator_tracking);
    std::vector<int> first_ids;
    for (const PointObservation& o : tracker.track(view(0), 0).points) first_ids.push_back(o.id);
    FeatureFrame last;
    for (int k = 1; k < frames; ++k) last = tracker.track(view(k), k * 50'000'000LL);
    int kept = 0;
    for (const PointObservation& o : last.points)
      kept += std::count(first_ids.begin(), first_ids.end(), o.id) > 0;
    return kept;
  };
  const int max_features = config.points.max_features;
  const int tracking = survivors(false, true);
  const int initialising = survivors(false, false);
  const int initialising_ending = survivors(true, false);
  RecordProperty("kept_tracking", tracking);
  RecordProperty("kept_initialising", initialising);
  // Frame to frame the corners track: without the anchors' end, nearly all stay.
  EXPECT_GT(initialising, max_features * 8 / 10);
  // The first patches no longer match: the anchors end most tracks.
  EXPECT_LT(tracking, max_features / 4) << initialising << " kept before initialisation";
  EXPECT_EQ(initialising_ending, tracking) << "end_mismatched_before_init: true ends them too";
}
