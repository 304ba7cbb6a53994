// The warped patch sums of the anchored alignment: the AVX2 path gives the baseline's bits for
// any warp, window and position, and the sums are those of the bilinear samples.
#include <gtest/gtest.h>

#include <cstring>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "alvio/frontend/warped_patch_sums.h"
#include "test_images.h"

using namespace alvio;

namespace {

std::vector<float> randomPacked(int n, int seed) {
  std::vector<float> packed(std::size_t(n) * n * 8);
  cv::RNG rng(seed);
  for (float& x : packed) x = rng.uniform(-40.f, 40.f);
  return packed;
}

struct Sums {
  float s2 = 0, sums[8] = {};
};

Sums run(const cv::Mat& image, const Eigen::Matrix2d& A, double qx, double qy, int n,
         const std::vector<float>& packed, Vectors vectors) {
  Sums out;
  warpedPatchSums(image, A, qx, qy, n, packed.data(), &out.s2, out.sums, vectors);
  return out;
}

bool sameBits(const Sums& a, const Sums& b) {
  return std::memcmp(&a, &b, sizeof(Sums)) == 0;
}

}  // namespace

TEST(WarpedPatchSums, WidestVectorsGiveTheBaselinesBits) {
  const cv::Mat image = test::blurredNoise(cv::Size(160, 120), 1, 1.0);
  cv::RNG rng(2);
  int compared = 0;
  for (const int n : {21, 15, 9, 7, 33}) {
    const std::vector<float> packed = randomPacked(n, n);
    for (int k = 0; k < 300; ++k) {
      Eigen::Matrix2d A;
      A << rng.uniform(0.7, 1.4), rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3),
          rng.uniform(0.7, 1.4);
      // Anywhere the whole warped window stays inside, down to the last rows and columns.
      const double reach = 1.8 * (n / 2) + 1;
      const double qx = rng.uniform(reach, image.cols - 1.02 - reach);
      const double qy = rng.uniform(reach, image.rows - 1.02 - reach);
      EXPECT_TRUE(sameBits(run(image, A, qx, qy, n, packed, Vectors::kWidest),
                           run(image, A, qx, qy, n, packed, Vectors::kBaseline)))
          << "n " << n << " at " << qx << ", " << qy;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 1500);
}

TEST(WarpedPatchSums, SumTheBilinearSamples) {
  const cv::Mat image = test::blurredNoise(cv::Size(64, 48), 3, 1.0);
  const int n = 9, h = n / 2;
  const std::vector<float> packed = randomPacked(n, 4);
  Eigen::Matrix2d A;
  A << 1.1, 0.2, -0.1, 0.9;
  const double qx = 30.3, qy = 20.6;
  double s2 = 0, sums[8] = {};
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const double u = qx + A(0, 0) * (c - h) + A(0, 1) * (r - h);
      const double v = qy + A(1, 0) * (c - h) + A(1, 1) * (r - h);
      const int iu = static_cast<int>(u), iv = static_cast<int>(v);
      const double fx = u - iu, fy = v - iv;
      const auto at = [&](int x, int y) { return double(image.at<uchar>(y, x)); };
      const double value = (1 - fy) * ((1 - fx) * at(iu, iv) + fx * at(iu + 1, iv)) +
                           fy * ((1 - fx) * at(iu, iv + 1) + fx * at(iu + 1, iv + 1));
      s2 += value * value;
      for (int i = 0; i < 8; ++i) sums[i] += value * packed[(r * n + c) * 8 + i];
    }
  for (const Vectors vectors : {Vectors::kWidest, Vectors::kBaseline}) {
    const Sums got = run(image, A, qx, qy, n, packed, vectors);
    EXPECT_NEAR(got.s2, s2, 1e-4 * s2);
    for (int i = 0; i < 8; ++i) EXPECT_NEAR(got.sums[i], sums[i], 0.5) << i;
  }
}
