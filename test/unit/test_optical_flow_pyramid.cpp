// alvio::buildOpticalFlowPyramid8u builds cv::buildOpticalFlowPyramid's pyramid with gradients
// byte for byte, borders included, and falls back to OpenCV where it does not apply;
// alvio::PyramidHistory builds each frame's pyramid into the buffers from two frames back.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <string>

#include "alvio/frontend/optical_flow_pyramid.h"
#include "alvio/frontend/pyramid_history.h"
#include "test_support.h"

using namespace alvio;

namespace {

// Noise, blurred a little: every gradient value and sign occurs, up to the extremes.
cv::Mat noise(cv::Size size, int seed) {
  cv::RNG rng(seed);
  cv::Mat image(size, CV_8UC1);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  if (seed % 2) cv::GaussianBlur(image, image, cv::Size(3, 3), 0.8);
  return image;
}

std::vector<cv::Mat> openCvPyramid(const cv::Mat& image, cv::Size window, int levels, int* built) {
  std::vector<cv::Mat> pyramid;
  *built = cv::buildOpticalFlowPyramid(image, pyramid, window, levels, true, cv::BORDER_REFLECT_101,
                                       cv::BORDER_CONSTANT, false);
  return pyramid;
}

// The whole buffer a pyramid entry is a view into, border included.
cv::Mat wholeOf(const cv::Mat& view) {
  cv::Size whole;
  cv::Point offset;
  view.locateROI(whole, offset);
  cv::Mat m = view;
  m.adjustROI(offset.y, whole.height - view.rows - offset.y, offset.x,
              whole.width - view.cols - offset.x);
  return m;
}

// Built into `actual`, which may hold an older pyramid.
void expectSamePyramid(const cv::Mat& image, cv::Size window, int levels,
                       std::vector<cv::Mat>&& actual = {}) {
  SCOPED_TRACE(testing::Message() << image.cols << "x" << image.rows << ", window " << window.width
                                  << "x" << window.height << ", levels " << levels);
  int expected_levels = -1;
  const std::vector<cv::Mat> expected = openCvPyramid(image, window, levels, &expected_levels);
  EXPECT_EQ(buildOpticalFlowPyramid8u(image, window, levels, &actual), expected_levels);
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k) {
    SCOPED_TRACE(testing::Message() << "pyramid entry " << k);
    ASSERT_EQ(actual[k].type(), expected[k].type());
    ASSERT_EQ(actual[k].size(), expected[k].size());
    const cv::Mat a = wholeOf(actual[k]), e = wholeOf(expected[k]);
    ASSERT_EQ(a.size(), e.size());
    EXPECT_EQ(cv::norm(a, e, cv::NORM_INF), 0.0);
  }
}

}  // namespace

TEST(OpticalFlowPyramid, SameAsOpenCvOnNoiseForTheTrackersWindowsAndLevels) {
  int seed = 0;
  for (cv::Size size : {cv::Size(752, 480), cv::Size(101, 77), cv::Size(64, 45)})
    for (cv::Size window : {cv::Size(21, 21), cv::Size(15, 15), cv::Size(9, 13)})
      for (int levels : {0, 1, 3, 5}) expectSamePyramid(noise(size, seed++), window, levels);
}

TEST(OpticalFlowPyramid, SameAsOpenCvOnTheSharedEurocFrames) {
  const std::vector<std::string> images = test::sharedEurocImages();
  if (images.empty()) GTEST_SKIP() << "shared EuRoC images not found (../shared/data)";
  for (const std::string& path : images) {
    const cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(image.empty()) << path;
    expectSamePyramid(image, cv::Size(21, 21), 3);
  }
}

TEST(OpticalFlowPyramid, AViewIntoALargerImageIsCopiedNotShared) {
  const cv::Mat big = noise(cv::Size(300, 200), 3);
  const cv::Mat view = big(cv::Rect(40, 30, 200, 120));
  expectSamePyramid(view, cv::Size(21, 21), 2);
  std::vector<cv::Mat> pyramid;
  buildOpticalFlowPyramid8u(view, cv::Size(21, 21), 2, &pyramid);
  EXPECT_NE(pyramid[0].data, view.data);
}

TEST(OpticalFlowPyramid, ImagesNoLargerThanTheWindowGoToOpenCv) {
  // A border wider than the image: OpenCV reflects it more than once.
  expectSamePyramid(noise(cv::Size(21, 40), 4), cv::Size(21, 21), 2);
  expectSamePyramid(noise(cv::Size(12, 9), 5), cv::Size(15, 15), 1);
}

TEST(OpticalFlowPyramid, GradientsOfThinImagesAsOpenCvs) {
  // One or two rows or columns: the reflection falls back on the row or column itself.
  for (cv::Size size : {cv::Size(1, 1), cv::Size(1, 7), cv::Size(9, 1), cv::Size(2, 2),
                        cv::Size(33, 2), cv::Size(17, 3)}) {
    SCOPED_TRACE(testing::Message() << size.width << "x" << size.height);
    const cv::Mat image = noise(size, 7);
    std::vector<cv::Mat> expected;
    cv::buildOpticalFlowPyramid(image, expected, cv::Size(3, 3), 0, true, cv::BORDER_REFLECT_101,
                                cv::BORDER_CONSTANT, false);
    cv::Mat actual(size, CV_16SC2);
    scharrGradients(image, actual);
    EXPECT_EQ(cv::norm(actual, expected[1], cv::NORM_INF), 0.0);
  }
}

TEST(OpticalFlowPyramid, RefillsAnOlderPyramidWhereNothingElseHoldsItsBuffers) {
  const cv::Size window(21, 21);
  std::vector<cv::Mat> pyramid;
  buildOpticalFlowPyramid8u(noise(cv::Size(160, 120), 11), window, 2, &pyramid);
  const uchar* image_buffer = pyramid[0].data;
  const cv::Mat held = pyramid[1];  // the first gradients, still in use elsewhere
  const cv::Mat held_copy = held.clone();
  const cv::Mat next = noise(cv::Size(160, 120), 12);
  std::vector<cv::Mat> refilled = pyramid;
  pyramid.clear();
  buildOpticalFlowPyramid8u(next, window, 2, &refilled);
  EXPECT_EQ(refilled[0].data, image_buffer);
  EXPECT_NE(refilled[1].data, held.data);
  EXPECT_EQ(cv::norm(held, held_copy, cv::NORM_INF), 0.0);
  expectSamePyramid(next, window, 2, std::move(refilled));
  // Another size or window: new buffers of the right shape.
  std::vector<cv::Mat> other;
  buildOpticalFlowPyramid8u(next, window, 2, &other);
  expectSamePyramid(noise(cv::Size(100, 90), 13), window, 2, std::move(other));
  buildOpticalFlowPyramid8u(next, window, 2, &other);
  expectSamePyramid(next, cv::Size(15, 15), 3, std::move(other));
}

TEST(PyramidHistory, EachFrameRefillsTheBuffersOfTheOneTwoFramesBack) {
  const cv::Size window(21, 21);
  PyramidHistory history;
  EXPECT_TRUE(history.previous().empty());
  std::vector<const uchar*> buffers;  // each frame's level-0 image buffer
  std::vector<cv::Mat> frames;
  for (int k = 0; k < 4; ++k) {
    frames.push_back(noise(cv::Size(160, 120), 20 + k));
    const std::vector<cv::Mat>& current = history.build(frames.back(), window, 2);
    int levels = -1;
    const std::vector<cv::Mat> expected = openCvPyramid(frames.back(), window, 2, &levels);
    ASSERT_EQ(current.size(), expected.size());
    EXPECT_EQ(cv::norm(current[1], expected[1], cv::NORM_INF), 0.0) << "frame " << k;
    EXPECT_NE(current[0].data, frames.back().data) << "built into the caller's image";
    if (k > 0) {
      // The previous frame's pyramid is intact while this one is built.
      ASSERT_FALSE(history.previous().empty());
      EXPECT_EQ(history.previous()[0].data, buffers[k - 1]);
      EXPECT_EQ(cv::norm(history.previous()[0], frames[k - 1], cv::NORM_INF), 0.0);
    }
    if (k > 1) {
      EXPECT_EQ(current[0].data, buffers[k - 2]) << "frame " << k;
    }
    buffers.push_back(current[0].data);
    history.advance();
  }
  history.forgetPrevious();
  EXPECT_TRUE(history.previous().empty());
  // Without a previous pyramid the next one is still built, and is the previous after that.
  history.build(frames[0], window, 2);
  history.advance();
  ASSERT_FALSE(history.previous().empty());
  EXPECT_EQ(cv::norm(history.previous()[0], frames[0], cv::NORM_INF), 0.0);
}
