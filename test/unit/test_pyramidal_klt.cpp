// alvio::trackPyramidalKlt gives cv::calcOpticalFlowPyrLK's tracks bit for bit, on the
// pyramids alvio builds and through its fallbacks, and it tracks a known shift.
#include <gtest/gtest.h>

#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <string>

#include "alvio/frontend/pyramidal_klt.h"
#include "test_images.h"
#include "test_support.h"

using namespace alvio;

namespace {

// Blurred noise: texture at several scales, as KLT needs.
cv::Mat texture(cv::Size size, int seed) {
  return test::stretched(test::blurredNoise(size, seed, 2.0));
}

// Black and white squares of random sizes, slightly blurred: steep gradients and large
// differences, whose products and sums exceed a float's 24 bits, so that the order of KLT's
// float sums shows in its tracks.
cv::Mat blocks(cv::Size size, int seed) {
  cv::RNG rng(seed);
  cv::Mat image(size, CV_8UC1, cv::Scalar(0));
  for (int i = 0; i < 600; ++i) {
    const int side = rng.uniform(4, 24);
    const cv::Point corner(rng.uniform(0, size.width), rng.uniform(0, size.height));
    cv::rectangle(image, cv::Rect(corner, cv::Size(side, side)),
                  cv::Scalar(rng.uniform(0, 2) * 255), cv::FILLED);
  }
  cv::GaussianBlur(image, image, cv::Size(0, 0), 0.7);
  return image;
}

cv::Mat shifted(const cv::Mat& image, cv::Point2f shift) {
  const cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, shift.x, 0, 1, shift.y);
  cv::Mat out;
  cv::warpAffine(image, out, M, image.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT_101);
  return out;
}

std::vector<cv::Mat> pyramidOf(const cv::Mat& image, cv::Size window, int levels,
                               bool derivatives = true) {
  std::vector<cv::Mat> pyramid;
  cv::buildOpticalFlowPyramid(image, pyramid, window, levels, derivatives, cv::BORDER_REFLECT_101,
                              cv::BORDER_CONSTANT, false);
  return pyramid;
}

// A grid over the image and past its borders (windows partly or wholly outside), plus
// random points.
std::vector<cv::Point2f> probePoints(cv::Size size) {
  std::vector<cv::Point2f> points;
  for (float y = -25.3f; y < size.height + 25; y += 17.7f)
    for (float x = -25.6f; x < size.width + 25; x += 23.1f) points.emplace_back(x, y);
  cv::RNG rng(5);
  for (int i = 0; i < 200; ++i)
    points.emplace_back(rng.uniform(0.f, float(size.width)), rng.uniform(0.f, float(size.height)));
  return points;
}

struct Case {
  cv::Size window;
  int levels;
  cv::TermCriteria stop;
  bool initial_flow;
};

// Points whose position or status differ from OpenCV's (positions compared bit for bit).
int differingFromOpenCv(const std::vector<cv::Mat>& from, const std::vector<cv::Mat>& to,
                        const std::vector<cv::Point2f>& points, const Case& c,
                        Vectors vectors = Vectors::kWidest) {
  std::vector<cv::Point2f> expected, got;
  if (c.initial_flow) {
    for (const cv::Point2f& p : points) expected.push_back(p + cv::Point2f(1.6f, -0.9f));
    got = expected;
  }
  std::vector<uchar> expected_status, got_status;
  cv::calcOpticalFlowPyrLK(from, to, points, expected, expected_status, cv::noArray(), c.window,
                           c.levels, c.stop, c.initial_flow ? cv::OPTFLOW_USE_INITIAL_FLOW : 0);
  trackPyramidalKlt(from, to, points, &got, &got_status, c.window, c.levels, c.stop, c.initial_flow,
                    vectors);
  if (got.size() != expected.size() || got_status.size() != expected_status.size()) return -1;
  int differing = 0;
  for (std::size_t i = 0; i < got.size(); ++i)
    if (got_status[i] != expected_status[i] ||
        std::memcmp(&got[i], &expected[i], sizeof(cv::Point2f)) != 0)
      ++differing;
  return differing;
}

const cv::TermCriteria kDefaultStop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);

// An OpenCV built with FMA in its baseline fuses KLT's float sums, which alvio keeps apart as
// Debian's SSE2 build does: then the tracks agree only to rounding.
bool openCvFusesMultiplyAdd() {
  const std::string info = cv::getBuildInformation();
  const std::size_t at = info.find("Baseline:");
  if (at == std::string::npos) return false;
  const std::string baseline = info.substr(at, info.find('\n', at) - at);
  return baseline.find("FMA3") != std::string::npos || baseline.find("AVX2") != std::string::npos;
}

#define SKIP_IF_OPENCV_FUSES()  \
  if (openCvFusesMultiplyAdd()) \
  GTEST_SKIP() << "this OpenCV's baseline has FMA: its KLT sums differ from SSE2's by rounding"

}  // namespace

TEST(PyramidalKlt, GivesOpenCvsTracksBitForBit) {
  SKIP_IF_OPENCV_FUSES();
  const cv::Size size(752, 480);
  const cv::Mat a = texture(size, 1);
  const cv::Mat b = shifted(a, {3.4f, -2.2f});
  const std::vector<cv::Point2f> points = probePoints(size);
  // The trackers' windows (21 points, 15 lines), the tail-less 8 and 16, odd sizes, and
  // non-square windows; all levels or a few; other stopping rules.
  const std::vector<Case> cases = {
      {{21, 21}, 3, kDefaultStop, false},
      {{21, 21}, 3, kDefaultStop, true},
      {{15, 15}, 1, kDefaultStop, true},
      {{15, 15}, 3, kDefaultStop, false},
      {{8, 8}, 2, kDefaultStop, false},
      {{16, 16}, 2, kDefaultStop, false},
      {{9, 13}, 2, kDefaultStop, false},
      {{31, 7}, 0, kDefaultStop, false},
      {{21, 21}, 3, cv::TermCriteria(cv::TermCriteria::COUNT, 5, 0), false},
      {{21, 21}, 2, cv::TermCriteria(cv::TermCriteria::EPS, 0, 0.1), false},
  };
  const cv::Mat c0 = blocks(size, 7);
  const cv::Mat c1 = shifted(c0, {2.6f, 1.7f});
  for (const Case& c : cases)
    for (const bool steep : {false, true}) {
      const std::vector<cv::Mat> from = pyramidOf(steep ? c0 : a, c.window, c.levels);
      const std::vector<cv::Mat> to = pyramidOf(steep ? c1 : b, c.window, c.levels);
      // The widest vectors (16 pixels at a time where the CPU has AVX2) and SSE2's 8.
      for (const Vectors vectors : {Vectors::kWidest, Vectors::kBaseline})
        EXPECT_EQ(differingFromOpenCv(from, to, points, c, vectors), 0)
            << "window " << c.window << ", levels " << c.levels << ", initial flow "
            << c.initial_flow << (vectors == Vectors::kBaseline ? ", SSE2" : ", widest")
            << (steep ? ", squares" : ", blurred noise");
    }
}

TEST(PyramidalKlt, GivesOpenCvsTracksOnRealEuRoCFrames) {
  SKIP_IF_OPENCV_FUSES();
  const std::vector<std::string> images = test::sharedEurocImages();
  if (images.size() < 2) GTEST_SKIP() << "shared EuRoC images not found (../shared/data)";
  for (std::size_t k = 0; k + 1 < images.size(); ++k) {
    const cv::Mat a = cv::imread(images[k], cv::IMREAD_GRAYSCALE);
    const cv::Mat b = cv::imread(images[k + 1], cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(a.empty() || b.empty()) << images[k];
    if (a.size() != b.size()) continue;
    std::vector<cv::Point2f> corners;
    cv::goodFeaturesToTrack(a, corners, 150, 0.01, 30);
    for (const cv::Size window : {cv::Size(21, 21), cv::Size(15, 15)}) {
      const Case c{window, 3, kDefaultStop, false};
      for (const Vectors vectors : {Vectors::kWidest, Vectors::kBaseline})
        EXPECT_EQ(differingFromOpenCv(pyramidOf(a, window, 3), pyramidOf(b, window, 3), corners, c,
                                      vectors),
                  0)
            << images[k] << ", window " << window
            << (vectors == Vectors::kBaseline ? ", SSE2" : ", widest");
    }
  }
}

TEST(PyramidalKlt, TracksAKnownShift) {
  const cv::Size size(752, 480);
  const cv::Point2f shift(3.4f, -2.2f);
  const cv::Mat a = texture(size, 2);
  const cv::Mat b = shifted(a, shift);
  const cv::Size window(21, 21);
  std::vector<cv::Point2f> points;
  for (float y = 60; y < size.height - 60; y += 40)
    for (float x = 60; x < size.width - 60; x += 40) points.emplace_back(x, y);
  std::vector<cv::Point2f> tracked;
  std::vector<uchar> status;
  trackPyramidalKlt(pyramidOf(a, window, 3), pyramidOf(b, window, 3), points, &tracked, &status,
                    window, 3, kDefaultStop, false);
  ASSERT_EQ(tracked.size(), points.size());
  // Within a tenth of a pixel: KLT's bilinear fixed point against the cubic shift (the worst
  // point is about 0.06 px off).
  for (std::size_t i = 0; i < points.size(); ++i) {
    ASSERT_TRUE(status[i]) << points[i];
    EXPECT_LT(cv::norm(tracked[i] - points[i] - shift), 0.1) << points[i];
  }
}

TEST(PyramidalKlt, OtherPyramidsAndNarrowWindowsGoToOpenCv) {
  const cv::Size size(320, 240);
  const cv::Mat a = texture(size, 3);
  const cv::Mat b = shifted(a, {1.5f, 0.5f});
  const std::vector<cv::Point2f> points = probePoints(size);
  // Pyramids without gradients, and windows narrower than 8 pixels.
  const Case plain{{21, 21}, 2, kDefaultStop, false};
  EXPECT_EQ(differingFromOpenCv(pyramidOf(a, plain.window, 2, false),
                                pyramidOf(b, plain.window, 2, false), points, plain),
            0);
  const Case narrow{{5, 5}, 2, kDefaultStop, true};
  EXPECT_EQ(differingFromOpenCv(pyramidOf(a, narrow.window, 2), pyramidOf(b, narrow.window, 2),
                                points, narrow),
            0);
}

TEST(PyramidalKlt, NoPointsGiveEmptyResults) {
  const cv::Mat a = texture(cv::Size(64, 48), 4);
  const std::vector<cv::Mat> pyramid = pyramidOf(a, cv::Size(15, 15), 1);
  std::vector<cv::Point2f> tracked = {{1, 2}};
  std::vector<uchar> status = {1};
  trackPyramidalKlt(pyramid, pyramid, {}, &tracked, &status, cv::Size(15, 15), 1, kDefaultStop,
                    false);
  EXPECT_TRUE(tracked.empty());
  EXPECT_TRUE(status.empty());
}
