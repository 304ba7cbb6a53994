// Edge refinement: a segment detected up to a pixel off its edge is moved onto the edge that
// the full-resolution image shows, keeps its extent and direction, and is left alone where
// there is no single edge to move to.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "alvio/lines/edge_refinement.h"

using namespace alvio;

namespace {
const cv::Size kSize(320, 240);

// An image split by the line through `point` with unit normal `normal`: `dark` where the signed
// distance is below 0, `bright` above, a `stripe_px` wide dark stripe starting `stripe_at_px`
// into the bright side if wanted. Each pixel averages 8 x 8 sub-samples (a camera's
// anti-aliasing).
cv::Mat edgeImage(const Eigen::Vector2d& point, const Eigen::Vector2d& normal, int dark, int bright,
                  double stripe_at_px = -1, double stripe_px = 0) {
  cv::Mat img(kSize, CV_8UC1);
  for (int y = 0; y < kSize.height; ++y)
    for (int x = 0; x < kSize.width; ++x) {
      double sum = 0;
      for (int i = 0; i < 8; ++i)
        for (int j = 0; j < 8; ++j) {
          const Eigen::Vector2d p(x - 0.5 + (j + 0.5) / 8, y - 0.5 + (i + 0.5) / 8);
          const double d = normal.dot(p - point);
          const bool in_stripe =
              stripe_at_px >= 0 && d >= stripe_at_px && d < stripe_at_px + stripe_px;
          sum += (d < 0 || in_stripe) ? dark : bright;
        }
      img.at<uchar>(y, x) = cv::saturate_cast<uchar>(sum / 64);
    }
  return img;
}

struct TrueLine {
  Eigen::Vector2d point, normal;
  double distance(const Eigen::Vector2d& p) const { return std::abs(normal.dot(p - point)); }
};

TrueLine slantedLine() {
  const double a = 20.0 * M_PI / 180.0;  // the line's direction
  return {{160.3, 120.6}, {-std::sin(a), std::cos(a)}};
}

// A detection of `line`: its endpoints 80 px either side of the point, shifted across the line
// by `offset` and turned by `turn_deg` (up to 1.2 px off at the ends below).
LineSegment detectionOf(const TrueLine& line, double offset, double turn_deg) {
  const Eigen::Vector2d dir(line.normal.y(), -line.normal.x());
  const double t = turn_deg * M_PI / 180.0;
  const Eigen::Vector2d turned(std::cos(t) * dir.x() - std::sin(t) * dir.y(),
                               std::sin(t) * dir.x() + std::cos(t) * dir.y());
  const Eigen::Vector2d mid = line.point + offset * line.normal;
  return {mid - 80 * turned, mid + 80 * turned};
}
}  // namespace

TEST(EdgeRefinement, MovesAnOffsetSegmentOntoItsEdge) {
  const TrueLine line = slantedLine();
  const cv::Mat img = edgeImage(line.point, line.normal, 40, 200);
  for (double offset : {-0.8, -0.4, 0.0, 0.5, 0.8}) {
    for (double turn : {-0.3, 0.0, 0.3}) {
      LineSegment s = detectionOf(line, offset, turn);
      const LineSegment before = s;
      ASSERT_TRUE(refineSegmentToEdge(img, EdgeRefinementOptions(), &s))
          << "offset " << offset << ", turn " << turn;
      EXPECT_LT(line.distance(s.start), 0.1) << "offset " << offset << ", turn " << turn;
      EXPECT_LT(line.distance(s.end), 0.1) << "offset " << offset << ", turn " << turn;
      // The extent and the direction are the detector's.
      EXPECT_NEAR(s.length(), before.length(), 1.0);
      EXPECT_GT(s.direction().dot(before.direction()), 0.99);
    }
  }
}

TEST(EdgeRefinement, IgnoresANearbyEdgeOfTheOtherPolarity) {
  // A 2 px dark stripe 1.5 px into the bright side: its far border is an edge of the same
  // strength but of the opposite sign, 3.5 px from the segment's edge.
  const TrueLine line = slantedLine();
  const cv::Mat img = edgeImage(line.point, line.normal, 40, 200, 1.5, 2.0);
  LineSegment s = detectionOf(line, 0.7, 0.0);
  ASSERT_TRUE(refineSegmentToEdge(img, EdgeRefinementOptions(), &s));
  EXPECT_LT(line.distance(s.start), 0.15);
  EXPECT_LT(line.distance(s.end), 0.15);
}

TEST(EdgeRefinement, LeavesTheSegmentWhereThereIsNoEdge) {
  const TrueLine line = slantedLine();
  const LineSegment detected = detectionOf(line, 0.5, 0.0);
  // No contrast at all.
  LineSegment s = detected;
  EXPECT_FALSE(
      refineSegmentToEdge(cv::Mat(kSize, CV_8UC1, cv::Scalar(128)), EdgeRefinementOptions(), &s));
  EXPECT_EQ(s.start, detected.start);
  EXPECT_EQ(s.end, detected.end);
  // An edge, but 4 px away: beyond the search, so not this segment's.
  const cv::Mat far = edgeImage(line.point + 4.0 * line.normal, line.normal, 40, 200);
  EXPECT_FALSE(refineSegmentToEdge(far, EdgeRefinementOptions(), &s));
  EXPECT_EQ(s.start, detected.start);
  // Too short to sample.
  LineSegment tiny(line.point, line.point + Eigen::Vector2d(5, 0));
  EXPECT_FALSE(refineSegmentToEdge(edgeImage(line.point, line.normal, 40, 200),
                                   EdgeRefinementOptions(), &tiny));
}
