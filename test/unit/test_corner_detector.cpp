// The corner detector returns cv::goodFeaturesToTrack's corners, in its order, on textured,
// tied and masked images, and on real EuRoC frames when the shared data is here. Its response
// is summed exactly where OpenCV sums floats: two candidates whose OpenCV responses are
// within its rounding may swap places, nothing else may differ.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "alvio/frontend/corner_detector.h"
#include "test_images.h"
#include "test_support.h"

using namespace alvio;

namespace {
cv::Mat texture(cv::Size size, int seed) {
  return test::blurredNoise(size, seed, 2.0);
}

// Equal responses everywhere inside: the tie rule decides the order.
cv::Mat checkerboard(cv::Size size, int square) {
  cv::Mat img(size, CV_8UC1);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      img.at<uchar>(y, x) = ((x / square + y / square) % 2) ? 200 : 40;
  return img;
}

// The point tracker's mask: discs around corners it already tracks.
cv::Mat discMask(cv::Size size, int discs, int radius, int seed) {
  cv::Mat mask(size, CV_8UC1, cv::Scalar(255));
  cv::RNG rng(seed);
  for (int i = 0; i < discs; ++i)
    cv::circle(mask, {rng.uniform(0, size.width), rng.uniform(0, size.height)}, radius, 0, -1);
  return mask;
}

// OpenCV's responses agree within their rounding (relative 3e-5 measured; 1e-4 allowed).
bool nearlyTied(const cv::Mat& response, cv::Point2f a, cv::Point2f b) {
  const float ra = response.at<float>(cvRound(a.y), cvRound(a.x));
  const float rb = response.at<float>(cvRound(b.y), cvRound(b.x));
  return std::abs(ra - rb) <= 1e-4 * std::max(std::abs(ra), std::abs(rb));
}

void expectSameAsOpenCv(CornerDetector* detector, const cv::Mat& img, int max_corners,
                        double quality, double min_distance, const cv::Mat& mask) {
  std::vector<cv::Point2f> expected;
  cv::goodFeaturesToTrack(img, expected, max_corners, quality, min_distance, mask);
  const std::vector<cv::Point2f> got =
      detector->detect(img, max_corners, quality, min_distance, mask);
  const std::string where = "max " + std::to_string(max_corners) + ", distance " +
                            std::to_string(min_distance) + ", mask " +
                            (mask.empty() ? "no" : "yes");
  ASSERT_EQ(got.size(), expected.size()) << where;
  cv::Mat response;
  cv::cornerMinEigenVal(img, response, 3, 3);
  std::size_t differing = 0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    if (got[i] == expected[i]) continue;
    ++differing;
    EXPECT_TRUE(nearlyTied(response, got[i], expected[i]))
        << where << ": corner " << i << " is " << got[i] << ", OpenCV's " << expected[i];
  }
  // A swap of two near-ties shows up as two differing places; spacing can carry it a little
  // further. Anything more is not rounding.
  EXPECT_LE(differing, 2 + got.size() / 200) << where;
}
}  // namespace

TEST(CornerDetector, MatchesGoodFeaturesToTrackOnTexture) {
  const cv::Size size(752, 480);
  CornerDetector detector;  // one detector throughout: its buffers carry over
  for (int seed = 1; seed <= 3; ++seed) {
    const cv::Mat img = texture(size, seed);
    for (int max_corners : {1, 30, 150, 3000})
      for (double min_distance : {0.0, 5.0, 30.0}) {
        expectSameAsOpenCv(&detector, img, max_corners, 0.01, min_distance, cv::Mat());
        expectSameAsOpenCv(&detector, img, max_corners, 0.01, min_distance,
                           discMask(size, 120, 30, seed));
      }
  }
}

TEST(CornerDetector, MatchesGoodFeaturesToTrackWhereResponsesTie) {
  CornerDetector detector;
  const cv::Mat img = checkerboard({752, 480}, 16);
  for (int max_corners : {10, 150, 5000})
    for (double min_distance : {0.0, 3.0, 30.0})
      expectSameAsOpenCv(&detector, img, max_corners, 0.01, min_distance, cv::Mat());
}

TEST(CornerDetector, MatchesGoodFeaturesToTrackOnEurocFrames) {
  const std::vector<std::string> files = test::sharedEurocImages();
  if (files.size() < 5) GTEST_SKIP() << "real EuRoC images not found in the shared data: skipping";
  CornerDetector detector;
  for (int i = 0; i < 5; ++i) {
    const cv::Mat img = cv::imread(files[i], cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(img.empty()) << files[i];
    expectSameAsOpenCv(&detector, img, 150, 0.01, 30, cv::Mat());
    expectSameAsOpenCv(&detector, img, 40, 0.01, 30, discMask(img.size(), 110, 30, i));
  }
}

TEST(CornerDetector, EmptyWhenTheMaskCoversEverything) {
  CornerDetector detector;
  const cv::Mat img = texture({200, 100}, 7);
  EXPECT_TRUE(detector.detect(img, 50, 0.01, 10, cv::Mat::zeros(img.size(), CV_8UC1)).empty());
}

TEST(CornerDetector, ThresholdComesFromTheStrongestCornerInsideTheMask) {
  // A faint texture and one high-contrast square: with quality 0.2, the square's corners set a
  // threshold no texture corner reaches. Masked, the texture's own strongest sets it.
  cv::Mat img = texture({752, 480}, 5);
  img = img / 3 + 60;
  cv::rectangle(img, cv::Rect(300, 200, 60, 60), cv::Scalar(255), cv::FILLED);
  cv::Mat mask(img.size(), CV_8UC1, cv::Scalar(255));
  cv::rectangle(mask, cv::Rect(280, 180, 100, 100), cv::Scalar(0), cv::FILLED);
  CornerDetector detector;
  expectSameAsOpenCv(&detector, img, 150, 0.2, 10, cv::Mat());
  expectSameAsOpenCv(&detector, img, 150, 0.2, 10, mask);
  EXPECT_LE(detector.detect(img, 150, 0.2, 10, cv::Mat()).size(), 4u);
  EXPECT_GT(detector.detect(img, 150, 0.2, 10, mask).size(), 20u);
}
