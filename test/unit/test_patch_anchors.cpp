// Anchored patch refinement: it finds a sub-pixel shift under a change of brightness and
// contrast, refuses what it must not take (too far, another patch, off the image), and on a
// noisy sequence keeps the track's error bounded where frame-to-frame KLT lets it grow.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <vector>

#include "alvio/frontend/patch_anchors.h"

using namespace alvio;

namespace {
// A smooth random texture, grey levels from lo to hi.
cv::Mat texture(cv::Size size, int seed, double lo = 20, double hi = 235) {
  cv::Mat noise(size, CV_32FC1);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 2.0);
  cv::normalize(noise, noise, lo, hi, cv::NORM_MINMAX);
  return noise;
}

// `base` moved by (dx, dy) (content at x in base appears at x + d), times gain plus offset,
// plus white noise of sigma DN, as 8-bit.
cv::Mat shifted(const cv::Mat& base, double dx, double dy, double gain = 1, double offset = 0,
                double sigma = 0, int seed = 0) {
  cv::Mat out;
  const cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
  cv::warpAffine(base, out, M, base.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT);
  out = out * gain + offset;
  if (sigma > 0) {
    cv::Mat noise(out.size(), CV_32FC1);
    cv::RNG rng(seed);
    rng.fill(noise, cv::RNG::NORMAL, 0, sigma);
    out += noise;
  }
  cv::Mat u8;
  out.convertTo(u8, CV_8UC1);
  return u8;
}
}  // namespace

TEST(PatchAnchors, FindsSubPixelShiftUnderGainAndOffset) {
  const cv::Mat base = texture({200, 160}, 1);
  PatchAnchorOptions o;
  o.warp = "translation";  // the shift alone; the warps' own tests follow
  PatchAnchors anchors(o);
  const cv::Point2f p(100.3f, 80.6f);
  ASSERT_TRUE(anchors.anchor(7, shifted(base, 0, 0), p));
  const double dx = 0.37, dy = -0.62;
  const cv::Mat next = shifted(base, dx, dy, 1.3, -20);
  // Start where a drifted KLT would have put it.
  cv::Point2f q(p.x + dx + 0.55, p.y + dy - 0.35);
  ASSERT_EQ(anchors.refine(7, next, &q), Alignment::kAligned);
  EXPECT_NEAR(q.x, p.x + dx, 0.03);
  EXPECT_NEAR(q.y, p.y + dy, 0.03);
}

// A corner whose edges lie on one side of the point, seen again after the view changed: the
// shift alone is pulled towards those edges, a warp that models the change is not.
namespace {
// Position errors after aligning with each warp (translation, similarity, affine), the patch
// deformed by the 2x2 matrix L about the point, which then moved by (0.3, -0.2); 99 px where
// the alignment failed.
std::vector<double> warpErrors(const cv::Matx22d& L) {
  cv::Mat base = texture({200, 160}, 6, 90, 150);
  base(cv::Rect(100, 80, 100, 80)) += 60;  // a bright quadrant: a corner at (100, 80)
  const cv::Point2f p(100.0f, 80.0f);
  const cv::Mat first = shifted(base, 0, 0);
  const cv::Mat M =
      (cv::Mat_<double>(2, 3) << L(0, 0), L(0, 1), p.x - L(0, 0) * p.x - L(0, 1) * p.y, L(1, 0),
       L(1, 1), p.y - L(1, 0) * p.x - L(1, 1) * p.y);
  cv::Mat deformed;
  cv::warpAffine(base, deformed, M, base.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT);
  const cv::Mat next = shifted(deformed, 0.3, -0.2);
  const cv::Point2f truth(p.x + 0.3f, p.y - 0.2f);
  std::vector<double> errors;
  for (const char* warp : {"translation", "similarity", "affine"}) {
    PatchAnchorOptions o;
    o.warp = warp;
    PatchAnchors anchors(o);
    EXPECT_TRUE(anchors.anchor(1, first, p));
    cv::Point2f q(truth.x - 0.4f, truth.y + 0.3f);
    const bool aligned = anchors.refine(1, next, &q) == Alignment::kAligned;
    errors.push_back(aligned ? std::hypot(q.x - truth.x, q.y - truth.y) : 99.0);
  }
  return errors;
}
}  // namespace

TEST(PatchAnchors, SimilarityWarpFollowsAPatchSeenNearerAndTurned) {
  const double c = 1.08 * std::cos(4 * CV_PI / 180), s = 1.08 * std::sin(4 * CV_PI / 180);
  const std::vector<double> e = warpErrors(cv::Matx22d(c, s, -s, c));  // 8 % nearer, 4 deg
  EXPECT_LT(e[1], 0.1) << "translation only: " << e[0];
  EXPECT_LT(e[1], 0.25 * e[0]);
  EXPECT_LT(e[2], 0.1) << "affine";
}

TEST(PatchAnchors, AffineWarpFollowsASlantedPatch) {
  // Squeezed to 0.85 vertically and sheared, as the floor ahead is seen from nearer.
  const std::vector<double> e = warpErrors(cv::Matx22d(1.0, 0.12, 0.0, 0.85));
  EXPECT_LT(e[2], 0.1) << "translation " << e[0] << ", similarity " << e[1];
  EXPECT_LT(e[2], 0.5 * e[1]) << "translation " << e[0];
}

// A corner on an occluding edge is no 3D point: the background slides behind it, its patch
// stops matching, and the alignment says so (end_mismatched ends such tracks). A point on the
// moving surface itself keeps aligning.
TEST(PatchAnchors, ACornerOverASlidingBackgroundStopsMatching) {
  const cv::Mat background = texture({320, 200}, 7, 60, 200);
  const cv::Mat box = texture({320, 200}, 8, 60, 200);
  const cv::Rect box_rect(150, 60, 100, 100);  // its top-left corner starts at (150, 60)
  auto frame = [&](int k) {
    // The box moves 0.9 px a frame, the background behind it 0.2 px.
    cv::Mat img = shifted(background, 0.2 * k, 0);
    const cv::Mat moved_box = shifted(box, 0.9 * k, 0);
    cv::Mat mask = cv::Mat::zeros(img.size(), CV_8UC1);
    const cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, 0.9 * k, 0, 1, 0);
    cv::Mat box_mask = cv::Mat::zeros(img.size(), CV_8UC1);
    box_mask(box_rect).setTo(255);
    cv::warpAffine(box_mask, mask, M, img.size(), cv::INTER_NEAREST);
    moved_box.copyTo(img, mask);
    return img;
  };
  PatchAnchorOptions o;
  o.warp = "similarity";
  o.min_zncc = 0.7;
  PatchAnchors anchors(o);
  const cv::Point2f corner(150.f, 60.f), inside(200.f, 110.f);
  const cv::Mat first = frame(0);
  ASSERT_TRUE(anchors.anchor(1, first, corner));
  ASSERT_TRUE(anchors.anchor(2, first, inside));
  int corner_lost_at = -1;
  for (int k = 1; k <= 20; ++k) {
    const cv::Mat img = frame(k);
    cv::Point2f c(corner.x + 0.9f * k, corner.y), i(inside.x + 0.9f * k, inside.y);
    if (corner_lost_at < 0 && anchors.refine(1, img, &c) == Alignment::kMismatch)
      corner_lost_at = k;
    ASSERT_EQ(anchors.refine(2, img, &i), Alignment::kAligned) << "frame " << k;
    EXPECT_NEAR(i.x, inside.x + 0.9 * k, 0.1);
  }
  EXPECT_GT(corner_lost_at, 0) << "the occluding corner kept aligning for 20 frames";
  EXPECT_GE(corner_lost_at, 2) << "lost before the background had slid at all";
  RecordProperty("corner_lost_at_frame", corner_lost_at);
  EXPECT_LE(corner_lost_at, 15);
}

TEST(PatchAnchors, RefusesLargeShiftsOtherPatchesAndTheBorder) {
  const cv::Mat base = texture({200, 160}, 2);
  PatchAnchorOptions o;
  o.max_shift_px = 1.0;
  PatchAnchors anchors(o);
  const cv::Point2f p(90, 70);
  ASSERT_TRUE(anchors.anchor(1, shifted(base, 0, 0), p));
  // Once aligned, a patch that fails is a mismatch (before, it would be unconfirmed).
  cv::Point2f confirmed = p;
  ASSERT_EQ(anchors.refine(1, shifted(base, 0.3, 0), &confirmed), Alignment::kAligned);
  // The true position is 2.5 px from the start: the alignment may find it, but the move is
  // too large to be taken.
  const cv::Mat next = shifted(base, 2.5, 0);
  cv::Point2f q = p;
  EXPECT_EQ(anchors.refine(1, next, &q), Alignment::kMismatch);
  EXPECT_EQ(q, p);
  // Unrelated texture: no correlation.
  cv::Point2f r = p;
  EXPECT_EQ(anchors.refine(1, shifted(texture({200, 160}, 3), 0, 0), &r), Alignment::kMismatch);
  EXPECT_EQ(r, p);
  // No anchor for this id; and no anchor where the patch leaves the image.
  EXPECT_EQ(anchors.refine(2, next, &q), Alignment::kNoAnchor);
  cv::Point2f edge(4, 70);
  EXPECT_EQ(anchors.refine(1, next, &edge), Alignment::kOutside);
  EXPECT_FALSE(anchors.anchor(3, next, {3, 70}));
  EXPECT_FALSE(anchors.anchor(3, next, {90, 155}));
  EXPECT_EQ(anchors.size(), 1u);
}

TEST(PatchAnchors, APatchOfNoiseIsUnconfirmedNotMismatched) {
  // A plain wall: the patch's texture is the sensor noise, new in every frame.
  const cv::Mat wall(160, 200, CV_32FC1, cv::Scalar(128));
  PatchAnchors anchors(PatchAnchorOptions{});
  const cv::Point2f p(100, 80);
  ASSERT_TRUE(anchors.anchor(1, shifted(wall, 0, 0, 1, 0, 4, 1), p));
  for (int k = 1; k <= 3; ++k) {
    cv::Point2f q = p;
    EXPECT_EQ(anchors.refine(1, shifted(wall, 0, 0, 1, 0, 4, 1 + k), &q), Alignment::kUnconfirmed)
        << "frame " << k;
    EXPECT_EQ(q, p);
  }
  // A textured patch taken again where it failed is unconfirmed too, until it aligns.
  const cv::Mat base = texture({200, 160}, 4);
  ASSERT_TRUE(anchors.anchor(1, shifted(base, 0, 0), p));
  cv::Point2f q = p;
  EXPECT_EQ(anchors.refine(1, shifted(texture({200, 160}, 5), 0, 0), &q), Alignment::kUnconfirmed);
  ASSERT_EQ(anchors.refine(1, shifted(base, 0.2, 0.1), &q), Alignment::kAligned);
  q = p;
  EXPECT_EQ(anchors.refine(1, shifted(texture({200, 160}, 5), 0, 0), &q), Alignment::kMismatch);
}

TEST(PatchAnchors, ReanchorsAfterItsAgeAndForgetsLostTracks) {
  const cv::Mat img = shifted(texture({200, 160}, 4), 0, 0);
  PatchAnchorOptions o;
  o.reanchor_frames = 3;
  PatchAnchors anchors(o);
  ASSERT_TRUE(anchors.anchor(1, img, {50, 50}));
  ASSERT_TRUE(anchors.anchor(2, img, {120, 90}));
  anchors.tick();
  anchors.tick();
  EXPECT_FALSE(anchors.dueForReanchor(1));
  anchors.tick();
  EXPECT_TRUE(anchors.dueForReanchor(1));
  ASSERT_TRUE(anchors.anchor(1, img, {50, 50}));
  EXPECT_FALSE(anchors.dueForReanchor(1));
  EXPECT_TRUE(anchors.dueForReanchor(2));
  anchors.keepOnly({2});
  EXPECT_EQ(anchors.size(), 1u);
  EXPECT_TRUE(anchors.dueForReanchor(1));  // gone: anchor it again
}

// The purpose: frame-to-frame KLT on noisy images sums its errors along the track; aligning
// each position to the first frame's patch keeps it near the truth. A low-contrast texture
// (grey 100-140) under 3.5 DN of noise, like the rendered scenes' (docs/benchmarks.md).
// Every warp: the extra unknowns must not cost the plain shift its precision.
class LongTrack : public ::testing::TestWithParam<std::string> {};

TEST_P(LongTrack, KeepsTheErrorBounded) {
  const cv::Mat base = texture({320, 240}, 5, 100, 140);
  const int frames = 60;
  std::vector<cv::Point2f> start;
  for (int y = 50; y <= 190; y += 35)
    for (int x = 60; x <= 200; x += 35) start.emplace_back(x + 0.3f, y + 0.7f);
  PatchAnchorOptions o;
  o.reanchor_frames = 0;  // one patch for the whole track
  o.warp = GetParam();
  PatchAnchors anchors(o);
  cv::Mat prev = shifted(base, 0, 0, 1, 0, 3.5, 100);
  for (std::size_t i = 0; i < start.size(); ++i)
    ASSERT_TRUE(anchors.anchor(static_cast<int>(i), prev, start[i]));
  std::vector<cv::Point2f> klt = start, refined = start;
  for (int k = 1; k <= frames; ++k) {
    const double dx = 0.43 * k, dy = 0.21 * k;
    const cv::Mat next = shifted(base, dx, dy, 1, 0, 3.5, 100 + k);
    std::vector<cv::Point2f> out;
    std::vector<uchar> status;
    cv::calcOpticalFlowPyrLK(prev, next, klt, out, status, cv::noArray(), cv::Size(21, 21), 3);
    klt = out;
    // The refined track goes on from its own last position, as the tracker's does.
    cv::calcOpticalFlowPyrLK(prev, next, std::vector<cv::Point2f>(refined), out, status,
                             cv::noArray(), cv::Size(21, 21), 3);
    refined = out;
    for (std::size_t i = 0; i < refined.size(); ++i)
      anchors.refine(static_cast<int>(i), next, &refined[i]);
    prev = next;
  }
  auto rms = [&](const std::vector<cv::Point2f>& pts) {
    double s = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const double ex = pts[i].x - (start[i].x + 0.43 * frames);
      const double ey = pts[i].y - (start[i].y + 0.21 * frames);
      s += ex * ex + ey * ey;
    }
    return std::sqrt(s / pts.size());
  };
  const double e_klt = rms(klt), e_refined = rms(refined);
  RecordProperty("klt_rms_px", std::to_string(e_klt));
  RecordProperty("refined_rms_px", std::to_string(e_refined));
  EXPECT_GT(e_klt, 0.5) << "the sequence should make frame-to-frame KLT drift";
  EXPECT_LT(e_refined, 0.3) << "KLT alone: " << e_klt;
  EXPECT_LT(e_refined, 0.5 * e_klt);
}

INSTANTIATE_TEST_SUITE_P(PatchAnchors, LongTrack,
                         ::testing::Values("translation", "similarity", "affine"));
