// Exposure compensation: a sudden global brightness change must not cost the tracks.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "alvio/config/config.h"
#include "alvio/frontend/exposure_compensation.h"
#include "alvio/pipeline/front_end.h"
#include "test_support.h"

using namespace alvio;

namespace {

// Blurred noise: corners everywhere, like a textured wall.
cv::Mat texture(int width, int height, uint64_t seed) {
  cv::Mat image(height, width, CV_8UC1);
  cv::theRNG().state = seed;
  cv::randu(image, 0, 255);
  cv::GaussianBlur(image, image, cv::Size(0, 0), 2.0);
  cv::normalize(image, image, 20, 230, cv::NORM_MINMAX);
  return image;
}

cv::Mat scaled(const cv::Mat& image, double gain) {
  cv::Mat out;
  image.convertTo(out, CV_8U, gain);
  return out;
}

cv::Mat shifted(const cv::Mat& image, double dx) {
  cv::Mat out;
  const cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, 0);
  cv::warpAffine(image, out, M, image.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return out;
}

double meanOf(const cv::Mat& image) {
  return cv::mean(image)[0];
}

}  // namespace

TEST(ExposureCompensation, ScalesASuddenJumpBackAndKeepsTheLevel) {
  ExposureCompensation exposure(0.15);
  const cv::Mat bright = texture(320, 240, 1);
  cv::Mat buffer;
  EXPECT_EQ(exposure.apply(bright, meanOf(bright), &buffer).data, bright.data);
  const cv::Mat dark = scaled(bright, 0.3);
  for (int i = 0; i < 3; ++i) {  // the light stays low: every frame is brought back up
    const cv::Mat& seen = exposure.apply(dark, meanOf(dark), &buffer);
    EXPECT_NEAR(exposure.lastGain(), meanOf(bright) / meanOf(dark), 1e-9);
    EXPECT_NEAR(meanOf(seen), meanOf(bright), 2.0);
  }
  // The light comes back: nothing to compensate.
  EXPECT_EQ(exposure.apply(bright, meanOf(bright), &buffer).data, bright.data);
  EXPECT_EQ(exposure.lastGain(), 1.0);
}

TEST(ExposureCompensation, SlowDriftAndBlackFramesPassUntouched) {
  ExposureCompensation exposure(0.15);
  const cv::Mat base = texture(320, 240, 2);
  cv::Mat buffer;
  for (double gain = 1.0; gain > 0.3; gain *= 0.95) {  // 5 % darker per frame
    const cv::Mat frame = scaled(base, gain);
    EXPECT_EQ(exposure.apply(frame, meanOf(frame), &buffer).data, frame.data) << gain;
  }
  const cv::Mat black = cv::Mat::zeros(240, 320, CV_8UC1);
  const cv::Mat white(240, 320, CV_8UC1, cv::Scalar(255));
  EXPECT_EQ(exposure.apply(black, 0.0, &buffer).data, black.data);
  // After black, the next real frame sets the level afresh instead of being scaled to black.
  EXPECT_EQ(exposure.apply(base, meanOf(base), &buffer).data, base.data);
  // The same after saturated frames, which would otherwise push the next ones to white.
  EXPECT_EQ(exposure.apply(white, 255.0, &buffer).data, white.data);
  EXPECT_EQ(exposure.apply(base, meanOf(base), &buffer).data, base.data);
  ExposureCompensation off(0.0);
  const cv::Mat dark = scaled(base, 0.3);
  off.apply(base, meanOf(base), &buffer);
  EXPECT_EQ(off.apply(dark, meanOf(dark), &buffer).data, dark.data);
}

// The front end on a textured frame, then the same view 2 px on with the light at 30 %:
// with compensation most tracks survive; without, KLT loses them (the reason for it).
TEST(ExposureCompensation, FrontEndKeepsTracksThroughALightDrop) {
  Config config = Config::load(test::sourcePath("config/euroc.yaml"));
  config.estimator.use_lines = false;
  const cv::Mat first = texture(config.camera.width, config.camera.height, 3);
  const cv::Mat second = scaled(shifted(first, 2.0), 0.3);
  auto trackedIntoSecond = [&](double exposure_jump) {
    Config c = config;
    c.points.exposure_jump = exposure_jump;
    FrontEnd front_end(c);
    const FeatureFrame a = front_end.track(first, 1'000'000'000);
    const FeatureFrame b = front_end.track(second, 1'050'000'000);
    int kept = 0;
    for (const auto& p : b.points) kept += p.track_count > 1;
    EXPECT_GT(a.points.size(), 100u);
    EXPECT_NEAR(b.mean_intensity, meanOf(second), 1e-6) << "mean_intensity is the raw light";
    return kept;
  };
  const int with = trackedIntoSecond(0.15), without = trackedIntoSecond(0.0);
  EXPECT_GT(with, 100) << "with compensation";
  EXPECT_GT(with, 2 * without) << "with " << with << ", without " << without;
}
