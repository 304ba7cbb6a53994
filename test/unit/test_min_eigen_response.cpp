// MinEigenResponse gives cv::cornerMinEigenVal(image, response, 3, 3) up to OpenCV's float
// rounding, on every pixel, borders included, for any image size, and on real EuRoC frames
// when the shared data is here.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "alvio/frontend/min_eigen_response.h"
#include "test_images.h"
#include "test_support.h"

using namespace alvio;

namespace {

// Within OpenCV's rounding: 1e-4 of the image's strongest response (3e-5 measured).
void expectMatchesOpenCv(MinEigenResponse* calculator, const cv::Mat& img) {
  cv::Mat expected, got;
  cv::cornerMinEigenVal(img, expected, 3, 3);
  calculator->compute(img, &got);
  ASSERT_EQ(got.type(), CV_32F);
  ASSERT_EQ(got.size(), img.size());
  double strongest = 0;
  cv::minMaxLoc(cv::abs(expected), nullptr, &strongest);
  const double tolerance = 1e-4 * strongest;
  int bad = 0;
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      const float e = expected.at<float>(y, x), g = got.at<float>(y, x);
      if (std::abs(e - g) > tolerance && ++bad <= 5)
        ADD_FAILURE() << img.cols << "x" << img.rows << " at (" << x << ", " << y << "): " << g
                      << ", OpenCV " << e;
    }
  EXPECT_EQ(bad, 0) << img.cols << "x" << img.rows;
}
}  // namespace

TEST(MinEigenResponse, MatchesOpenCvOnTexturesOfAnySize) {
  MinEigenResponse calculator;  // one calculator throughout: its buffers carry over
  for (const cv::Size size :
       {cv::Size(752, 480), cv::Size(37, 23), cv::Size(3, 3), cv::Size(4, 7), cv::Size(640, 1)})
    for (double blur : {0.0, 1.5})
      expectMatchesOpenCv(&calculator, test::blurredNoise(size, size.area(), blur));
}

TEST(MinEigenResponse, MatchesOpenCvOnSaturatedEdges) {
  // The largest derivatives an 8-bit image has: the integer sums must not overflow.
  cv::Mat img(64, 64, CV_8UC1, cv::Scalar(0));
  cv::rectangle(img, {16, 16}, {47, 47}, cv::Scalar(255), -1);
  for (int y = 0; y < 64; y += 2) img.row(y).colRange(0, 8).setTo(255);
  MinEigenResponse calculator;
  expectMatchesOpenCv(&calculator, img);
}

TEST(MinEigenResponse, MatchesOpenCvOnEurocFrames) {
  const std::vector<std::string> files = test::sharedEurocImages();
  if (files.size() < 3) GTEST_SKIP() << "real EuRoC images not found in the shared data: skipping";
  MinEigenResponse calculator;
  for (std::size_t i = 0; i < 3; ++i) {
    const cv::Mat img = cv::imread(files[i], cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(img.empty()) << files[i];
    expectMatchesOpenCv(&calculator, img);
  }
}
