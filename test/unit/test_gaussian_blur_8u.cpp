// alvio::GaussianBlur8u gives cv::GaussianBlur's image bit for bit, in its own code where it
// can read OpenCV's weights, and through OpenCV otherwise.
#include <gtest/gtest.h>

#include <numeric>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "alvio/frontend/gaussian_blur_8u.h"
#include "test_support.h"

using namespace alvio;

namespace {
std::vector<cv::Mat> syntheticImages(cv::Size size) {
  cv::RNG rng(5);
  cv::Mat noise(size, CV_8UC1), checker(size, CV_8UC1), ramp(size, CV_8UC1), white(size, CV_8UC1);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  // 0 next to 255 everywhere: the largest sums, and every rounding case across a step.
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      checker.at<std::uint8_t>(y, x) = ((x / 3 + y / 2) % 2) ? 255 : 0;
      ramp.at<std::uint8_t>(y, x) =
          cv::saturate_cast<std::uint8_t>(x * 255.0 / size.width + rng.gaussian(6.0));
    }
  white.setTo(cv::Scalar(255));
  return {noise, checker, ramp, white};
}

// Pixels where GaussianBlur8u and cv::GaussianBlur differ on `image` (-1: the sizes differ).
int differingFromCvBlur(GaussianBlur8u& blur, int ksize, double sigma, const cv::Mat& image) {
  cv::Mat expected, got;
  cv::GaussianBlur(image, expected, cv::Size(ksize, ksize), sigma);
  blur.apply(image, got);
  return got.size() == expected.size() ? cv::countNonZero(got != expected) : -1;
}
}  // namespace

TEST(GaussianBlur8u, ReadsOpenCvsWeightsForTheLsdBlur) {
  // LSD at scale 0.5: sigma 0.6 / 0.5, an 11-tap kernel whose outer taps round to 0.
  GaussianBlur8u blur(11, 1.2);
  ASSERT_TRUE(blur.ownCode());
  const std::vector<std::uint16_t>& half = blur.halfKernel();
  ASSERT_GE(half.size(), 2u);
  const int sum = 2 * std::accumulate(half.begin(), half.end() - 1, 0) + half.back();
  EXPECT_EQ(sum, 256);
  for (std::size_t i = 1; i < half.size(); ++i) EXPECT_LT(half[i - 1], half[i]) << i;
}

TEST(GaussianBlur8u, GivesCvGaussianBlursImageBitForBit) {
  const std::vector<std::pair<int, double>> kernels = {{11, 1.2}, {7, 1.0}, {5, 0.8},
                                                       {13, 2.0}, {3, 1.0}, {9, 1.5}};
  for (const auto& [ksize, sigma] : kernels) {
    GaussianBlur8u blur(ksize, sigma);
    EXPECT_TRUE(blur.ownCode()) << ksize << " " << sigma;
    // 751 x 477: rows that end neither on 16 nor on 8 pixels.
    for (const cv::Size size : {cv::Size(752, 480), cv::Size(751, 477)}) {
      for (const cv::Mat& image : syntheticImages(size)) {
        EXPECT_EQ(differingFromCvBlur(blur, ksize, sigma, image), 0)
            << "ksize " << ksize << ", sigma " << sigma << ", " << size;
      }
    }
  }
}

TEST(GaussianBlur8u, GivesCvGaussianBlursImageOnRealEuRoCFrames) {
  const std::vector<std::string> images = test::sharedEurocImages();
  if (images.empty()) GTEST_SKIP() << "shared EuRoC images not found (../shared/data)";
  GaussianBlur8u blur(11, 1.2);
  ASSERT_TRUE(blur.ownCode());
  for (const std::string& path : images) {
    const cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(image.empty()) << path;
    EXPECT_EQ(differingFromCvBlur(blur, 11, 1.2, image), 0) << path;
  }
}

TEST(GaussianBlur8u, ImagesSmallerThanTheKernelAndViewsToo) {
  GaussianBlur8u blur(11, 1.2);
  // Smaller than the kernel: OpenCV's own border code.
  for (const cv::Mat& image : syntheticImages(cv::Size(9, 6)))
    EXPECT_EQ(differingFromCvBlur(blur, 11, 1.2, image), 0);
  // Just as large as the kernel: alvio's code, every pixel near a border.
  for (const cv::Mat& image : syntheticImages(cv::Size(11, 11)))
    EXPECT_EQ(differingFromCvBlur(blur, 11, 1.2, image), 0);
  // A view into a larger image: OpenCV takes the pixels around it as its border.
  const cv::Mat big = syntheticImages(cv::Size(200, 120))[0];
  EXPECT_EQ(differingFromCvBlur(blur, 11, 1.2, big(cv::Rect(30, 20, 120, 70))), 0);
}

TEST(GaussianBlur8u, KernelsItCannotReadGoToOpenCv) {
  // sigma 0.3 on 3 taps: a centre weight above 128 cannot be read back exactly.
  GaussianBlur8u blur(3, 0.3);
  EXPECT_FALSE(blur.ownCode());
  for (const cv::Mat& image : syntheticImages(cv::Size(64, 48)))
    EXPECT_EQ(differingFromCvBlur(blur, 3, 0.3, image), 0);
}
