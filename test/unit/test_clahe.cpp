// alvio::Clahe gives cv::CLAHE's image bit for bit, in its own path and in the fallback.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "alvio/frontend/clahe.h"
#include "test_support.h"

using namespace alvio;

namespace {
std::vector<cv::Mat> syntheticImages(cv::Size size) {
  cv::RNG rng(11);
  cv::Mat noise(size, CV_8UC1), dark(size, CV_8UC1), ramp(size, CV_8UC1), flat(size, CV_8UC1);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  rng.fill(dark, cv::RNG::UNIFORM, 0, 24);  // dim light: a few grey levels, heavy clipping
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      ramp.at<std::uint8_t>(y, x) =
          cv::saturate_cast<std::uint8_t>(x * 255.0 / size.width + rng.gaussian(4.0));
  flat.setTo(cv::Scalar(117));
  return {noise, dark, ramp, flat};
}

// Pixels where alvio's CLAHE and OpenCV's differ on `image` (-1: the sizes differ).
int differingFromCvClahe(Clahe& clahe, const cv::Ptr<cv::CLAHE>& reference, const cv::Mat& image) {
  cv::Mat expected, got;
  reference->apply(image, expected);
  clahe.apply(image, got);
  return got.size() == expected.size() ? cv::countNonZero(got != expected) : -1;
}
}  // namespace

TEST(Clahe, GivesCvClahesImageBitForBit) {
  const cv::Size size(752, 480);
  for (double clip : {3.0, 0.5, 40.0, 0.0}) {
    for (int tiles : {8, 4}) {
      Clahe clahe(clip, tiles);
      const cv::Ptr<cv::CLAHE> reference = cv::createCLAHE(clip, cv::Size(tiles, tiles));
      for (const cv::Mat& image : syntheticImages(size)) {
        EXPECT_EQ(differingFromCvClahe(clahe, reference, image), 0)
            << "clip " << clip << ", tiles " << tiles;
      }
    }
  }
}

TEST(Clahe, GivesCvClahesImageOnRealEuRoCFrames) {
  const std::vector<std::string> images = test::sharedEurocImages();
  if (images.empty()) GTEST_SKIP() << "shared EuRoC images not found (../shared/data)";
  Clahe clahe(3.0, 8);
  const cv::Ptr<cv::CLAHE> reference = cv::createCLAHE(3.0, cv::Size(8, 8));
  for (const std::string& path : images) {
    const cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(image.empty()) << path;
    EXPECT_EQ(differingFromCvClahe(clahe, reference, image), 0) << path;
  }
}

TEST(Clahe, RowsNotAMultipleOfEightEndInThePlainLoop) {
  // 750 = 3 x 250 columns: each row ends with six pixels past the last group of eight.
  Clahe clahe(3.0, 3);
  const cv::Ptr<cv::CLAHE> reference = cv::createCLAHE(3.0, cv::Size(3, 3));
  for (const cv::Mat& image : syntheticImages(cv::Size(750, 477))) {
    EXPECT_EQ(differingFromCvClahe(clahe, reference, image), 0);
  }
}

TEST(Clahe, ImagesTheTilesDoNotDivideGoToCvClahe) {
  // 750 and 479 are not multiples of 8: cv::CLAHE pads them itself.
  Clahe clahe(3.0, 8);
  const cv::Ptr<cv::CLAHE> reference = cv::createCLAHE(3.0, cv::Size(8, 8));
  for (const cv::Mat& image : syntheticImages(cv::Size(750, 479))) {
    EXPECT_EQ(differingFromCvClahe(clahe, reference, image), 0);
  }
  // And back to a size it handles itself, with new tables.
  for (const cv::Mat& image : syntheticImages(cv::Size(640, 480))) {
    EXPECT_EQ(differingFromCvClahe(clahe, reference, image), 0);
  }
}
