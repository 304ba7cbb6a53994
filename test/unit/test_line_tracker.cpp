// Line front end: detection, the optical-flow tracker's four track types on synthetic images,
// the descriptor baseline, undistortion and the options.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>

#include "alvio/camera/camera_model.h"
#include "alvio/common/error.h"
#include "alvio/config/config.h"
#include "alvio/config/yaml_reader.h"
#include "alvio/lines/descriptor_line_tracker.h"
#include "alvio/lines/image_undistorter.h"
#include "alvio/lines/line_detector.h"
#include "alvio/lines/linear_time_lsd.h"
#include "alvio/lines/optical_flow_line_tracker.h"
#include "synthetic_line_scene.h"
#include "test_support.h"

using namespace alvio;
using test::Bar;
using test::Occluder;

namespace {
constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;
const cv::Size kSize(752, 480);

LineSegment segmentOf(const LineObservation& o) {
  return {o.start_px, o.end_px};
}

// The two long edges of a bar (directions unspecified).
std::vector<LineSegment> longEdges(const Bar& bar, cv::Point2d offset) {
  const double a = bar.angle_deg / kRadToDeg;
  const Eigen::Vector2d u(std::cos(a), std::sin(a)), n(-std::sin(a), std::cos(a));
  const Eigen::Vector2d c(bar.centre.x + offset.x, bar.centre.y + offset.y);
  const double hl = bar.size.width / 2, ht = bar.size.height / 2;
  return {{c - hl * u + ht * n, c + hl * u + ht * n}, {c - hl * u - ht * n, c + hl * u - ht * n}};
}

// Does the observation lie on the edge's line (both endpoints within tol px, parallel)?
bool onLine(const LineObservation& o, const LineSegment& edge, double tol_px = 1.5) {
  return edge.distanceToLine(o.start_px) < tol_px && edge.distanceToLine(o.end_px) < tol_px;
}

std::map<int, LineObservation> byId(const LineFrame& f) {
  std::map<int, LineObservation> m;
  for (const auto& o : f.lines) EXPECT_TRUE(m.emplace(o.id, o).second) << "duplicate id " << o.id;
  return m;
}

// The type tests match detections on every frame, as the paper's tracker does.
LineTrackerOptions defaultOptions() {
  LineTrackerOptions o;
  o.flow.detect_every = 1;
  return o;
}

// A scene with bars of several orientations, all edges >= the minimum length (54 px).
const std::vector<Bar> kBars = {
    {{200, 150}, {220, 40}, 0},
    {{520, 140}, {180, 36}, 60},
    {{250, 350}, {260, 44}, -20},
    {{560, 360}, {140, 70}, 10},
};
}  // namespace

TEST(LineDetector, KeepsLongSegmentsLongestFirstUpToTheCap) {
  const test::SyntheticLineScene scene(kSize);
  const cv::Mat image = scene.render(kBars, {0, 0});
  LineDetectorOptions o;
  LineDetector detector(o, kSize);
  EXPECT_NEAR(detector.minLength(), 0.06 * std::hypot(752, 480), 1e-9);
  EXPECT_NEAR(detector.shortestLength(), 0.5 * detector.minLength(), 1e-9);
  const auto lines = detector.detect(image);
  // 2 long edges per bar + the 2 short (70 px) edges of the last one are new-line material.
  int long_enough = 0;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    EXPECT_GE(lines[i].length(), detector.shortestLength());
    long_enough += lines[i].length() >= detector.minLength();
    if (i > 0) {
      EXPECT_LE(lines[i].length(), lines[i - 1].length());
    }
  }
  EXPECT_GE(long_enough, 10);
  EXPECT_LE(long_enough, 14);
  o.max_lines = o.max_detections = 4;
  const auto capped = LineDetector(o, kSize).detect(image);
  ASSERT_EQ(capped.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(capped[i].length(), lines[i].length(), 1e-9);
}

TEST(LineDetector, LargerLsdQuantSkipsFaintEdges) {
  // Two vertical steps: a faint one (12 grey levels) at x = 250, a strong one (120) at x = 500.
  cv::Mat image(kSize, CV_8UC1, cv::Scalar(60));
  image.colRange(250, 500).setTo(72);
  image.colRange(500, kSize.width).setTo(192);
  const auto edgesAt = [&](double quant) {
    LineDetectorOptions o;
    o.lsd_quant = quant;
    std::set<int> xs;
    for (const LineSegment& s : LineDetector(o, kSize).detect(image))
      if (std::abs(s.start.x() - s.end.x()) < 2 && s.length() > 200)
        xs.insert(static_cast<int>(std::lround(s.midpoint().x() / 10) * 10));
    return xs;
  };
  EXPECT_EQ(edgesAt(2.0), (std::set<int>{250, 500}));
  EXPECT_EQ(edgesAt(8.0), (std::set<int>{500}));
}

TEST(LineDetector, AReferenceBrightnessKeepsADimFramesFaintEdges) {
  // A faint step (12 grey levels) at x = 250 and a strong one at x = 500, and the same frame
  // at 35 % of the light, where the faint step is 4 levels.
  cv::Mat bright(kSize, CV_8UC1, cv::Scalar(100));
  bright.colRange(250, 500).setTo(112);
  bright.colRange(500, kSize.width).setTo(200);
  cv::Mat dim;
  bright.convertTo(dim, CV_8UC1, 0.35);
  const double reference = cv::mean(bright)[0];
  const auto verticalEdges = [](const std::vector<LineSegment>& segments) {
    std::set<int> xs;
    for (const LineSegment& s : segments)
      if (std::abs(s.start.x() - s.end.x()) < 2 && s.length() > 200)
        xs.insert(static_cast<int>(std::lround(s.midpoint().x() / 10) * 10));
    return xs;
  };
  for (const char* method : {"lsd", "opencv_lsd"}) {
    SCOPED_TRACE(method);
    LineDetectorOptions o;
    o.method = method;
    LineDetector fixed(o, kSize);
    EXPECT_EQ(verticalEdges(fixed.detect(bright)), (std::set<int>{250, 500}));
    EXPECT_EQ(verticalEdges(fixed.detect(dim)), (std::set<int>{500}));  // what dim light loses

    o.lsd_reference_brightness = reference;
    LineDetector following(o, kSize);
    EXPECT_EQ(verticalEdges(following.detect(dim)), (std::set<int>{250, 500}));
    EXPECT_NEAR(following.lastQuant(), o.lsd_quant * cv::mean(dim)[0] / reference, 1e-12);
    // A frame as bright as the reference is detected exactly as without it.
    const auto a = fixed.detect(bright), b = following.detect(bright);
    EXPECT_EQ(following.lastQuant(), o.lsd_quant);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].start, b[i].start);
      EXPECT_EQ(a[i].end, b[i].end);
    }
    // A black frame's threshold stops at lsd_min_quant_scale.
    following.detect(cv::Mat(kSize, CV_8UC1, cv::Scalar(0)));
    EXPECT_EQ(following.lastQuant(), o.lsd_quant * o.lsd_min_quant_scale);
  }
}

TEST(LineDetector, AReferenceBrightnessIsAGreyLevel) {
  LineDetectorOptions o;
  o.lsd_reference_brightness = 300;
  EXPECT_NE(test::errorOf([&] { o.validate("lines.detector"); }).find("lsd_reference_brightness"),
            std::string::npos);
  // Every method takes it (FLD has no gradient threshold and ignores it, as the other lsd_ keys).
  o.lsd_reference_brightness = 110;
  for (const char* method : {"lsd", "opencv_lsd", "fld"}) {
    o.method = method;
    EXPECT_NO_THROW(o.validate("lines.detector")) << method;
  }
  o.lsd_min_quant_scale = 0;
  EXPECT_NE(test::errorOf([&] { o.validate("lines.detector"); }).find("lsd_min_quant_scale"),
            std::string::npos);
}

TEST(LineDetector, LsdOnAScaledImageFindsStepEdgesWhereTheyAre) {
  // A bright quadrant x > ex, y > ey, pixels shaded by the area they cover (pixel u spans
  // [u - 0.5, u + 0.5]), at ten sub-pixel positions. Before the scale shift, lsd_scale 0.5
  // put every edge 0.5 px up and left. The pyramid's half image is centred differently.
  for (const auto& [scale, pyramid] : {std::pair{1.0, false}, {0.5, false}, {0.5, true}}) {
    const std::string what = "scale " + std::to_string(scale) + (pyramid ? " (pyramid)" : "");
    double sum_x = 0, sum_y = 0;
    int n_x = 0, n_y = 0;
    for (int k = 0; k < 10; ++k) {
      const double ex = 300 + 0.1 * k, ey = 200.37 + 0.1 * k;
      cv::Mat image(kSize, CV_8UC1);
      for (int v = 0; v < image.rows; ++v)
        for (int u = 0; u < image.cols; ++u) {
          const double cover =
              std::clamp(u + 0.5 - ex, 0.0, 1.0) * std::clamp(v + 0.5 - ey, 0.0, 1.0);
          image.at<uint8_t>(v, u) = cv::saturate_cast<uint8_t>(60 + 140 * cover);
        }
      LineDetectorOptions o;
      o.lsd_scale = scale;
      o.lsd_pyramid_downscale = pyramid;
      for (const LineSegment& s : LineDetector(o, kSize).detect(image)) {
        const Eigen::Vector2d d = s.end - s.start;
        if (std::abs(d.x()) < 1 && s.length() > 100) {
          EXPECT_NEAR(s.midpoint().x(), ex, 0.2) << what;
          sum_x += s.midpoint().x() - ex;
          ++n_x;
        } else if (std::abs(d.y()) < 1 && s.length() > 100) {
          EXPECT_NEAR(s.midpoint().y(), ey, 0.2) << what;
          sum_y += s.midpoint().y() - ey;
          ++n_y;
        }
      }
    }
    ASSERT_EQ(n_x, 10) << what;
    ASSERT_EQ(n_y, 10) << what;
    EXPECT_NEAR(sum_x / n_x, 0.0, 0.05) << "mean x offset, " << what;
    EXPECT_NEAR(sum_y / n_y, 0.0, 0.05) << "mean y offset, " << what;
  }
}

namespace {
// Does `b` have a segment with both endpoints within 1 px of `s`'s (either way round)?
bool hasCounterpart(const cv::Vec4f& s, const std::vector<cv::Vec4f>& b) {
  return std::any_of(b.begin(), b.end(), [&](const cv::Vec4f& t) {
    return std::hypot(s[0] - t[0], s[1] - t[1]) < 1 && std::hypot(s[2] - t[2], s[3] - t[3]) < 1;
  });
}
double lengthOf(const cv::Vec4f& s) {
  return std::hypot(s[2] - s[0], s[3] - s[1]);
}
// Does `b` have a segment on the same line as `s` (both endpoints within 1 px of it) that
// covers at least half of the shorter of the two?
bool hasCollinearCounterpart(const cv::Vec4f& s, const std::vector<cv::Vec4f>& b) {
  const LineSegment a({s[0], s[1]}, {s[2], s[3]});
  return std::any_of(b.begin(), b.end(), [&](const cv::Vec4f& t) {
    const LineSegment c({t[0], t[1]}, {t[2], t[3]});
    return a.distanceToLine(c.start) < 1 && a.distanceToLine(c.end) < 1 &&
           projectedOverlap(a, c) >= 0.5 * std::min(a.length(), c.length());
  });
}

using Detect = std::function<void(const cv::Mat&, std::vector<cv::Vec4f>*)>;
using Counterpart = std::function<bool(const cv::Vec4f&, const std::vector<cv::Vec4f>&)>;
struct Agreement {
  int first = 0, first_found = 0, second = 0, second_found = 0;
};
// Runs both detectors on each image and counts, for each, its segments at least as long as
// the tracker keeps that have a counterpart among the other's.
Agreement compareOnImages(const std::vector<cv::Mat>& images, const Detect& first,
                          const Detect& second, const Counterpart& counterpart) {
  const double shortest = LineDetector(LineDetectorOptions(), kSize).shortestLength();
  Agreement n;
  for (const cv::Mat& image : images) {
    std::vector<cv::Vec4f> a, b;
    first(image, &a);
    second(image, &b);
    for (const cv::Vec4f& s : a)
      if (lengthOf(s) >= shortest) n.first_found += counterpart(s, b), ++n.first;
    for (const cv::Vec4f& s : b)
      if (lengthOf(s) >= shortest) n.second_found += counterpart(s, a), ++n.second;
  }
  return n;
}
// Ten of the real EuRoC frames, spread over the list.
std::vector<cv::Mat> tenRealFrames(const std::vector<std::string>& files) {
  std::vector<cv::Mat> images;
  for (std::size_t i = 0; i < files.size(); i += files.size() / 10) {
    images.push_back(cv::imread(files[i], cv::IMREAD_GRAYSCALE));
    EXPECT_FALSE(images.back().empty()) << files[i];
  }
  return images;
}
// alvio's LSD and OpenCV's without refinement, with the default options, must find nearly all
// of each other's segments on `images`.
void expectOpenCvsSegments(const std::vector<cv::Mat>& images) {
  const LineDetectorOptions o;  // the defaults: scale 0.5, sigma 0.6, quant 2
  const auto opencv = cv::createLineSegmentDetector(cv::LSD_REFINE_NONE, o.lsd_scale,
                                                    o.lsd_sigma_scale, o.lsd_quant);
  LinearTimeLsd linear(o.lsd_scale, o.lsd_sigma_scale, o.lsd_quant);
  const Agreement n = compareOnImages(
      images,
      [&](const cv::Mat& image, std::vector<cv::Vec4f>* out) { opencv->detect(image, *out); },
      [&](const cv::Mat& image, std::vector<cv::Vec4f>* out) { linear.detect(image, out); },
      hasCounterpart);
  std::cout << n.first_found << " of OpenCV's " << n.first << " segments found, " << n.second_found
            << " of ours " << n.second << " found by OpenCV\n";
  ASSERT_GT(n.first, 500);
  EXPECT_GE(n.first_found, 0.98 * n.first);
  EXPECT_GE(n.second_found, 0.98 * n.second);
}
// Random quadrilaterals from faint (4 grey levels) to strong contrast (200) over sensor noise:
// gradients both inside and beyond the detector's table of small gradients.
std::vector<cv::Mat> quadrilateralImages(int count) {
  cv::RNG rng(7);
  std::vector<cv::Mat> images;
  for (int i = 0; i < count; ++i) {
    cv::Mat image(kSize, CV_8UC1, cv::Scalar(rng.uniform(40, 200)));
    for (int q = 0; q < 25; ++q) {
      std::vector<cv::Point> corners;
      const cv::Point centre(rng.uniform(0, kSize.width), rng.uniform(0, kSize.height));
      for (int c = 0; c < 4; ++c)
        corners.push_back(centre + cv::Point(rng.uniform(-150, 150), rng.uniform(-150, 150)));
      const int contrast = q % 5 == 0 ? 200 : rng.uniform(4, 60);
      cv::fillConvexPoly(
          image, corners,
          cv::Scalar(std::clamp(rng.uniform(0, 2) ? contrast : 255 - contrast, 0, 255)),
          cv::LINE_AA);
    }
    cv::Mat noise(kSize, CV_8SC1);
    rng.fill(noise, cv::RNG::NORMAL, 0, 2);
    cv::add(image, noise, image, cv::noArray(), CV_8U);
    images.push_back(image);
  }
  return images;
}
}  // namespace

TEST(LinearTimeLsd, FindsOpenCvsSegmentsOnRealEuRoCFrames) {
  // The same algorithm and constants as OpenCV's LSD without refinement; only seeds of one
  // gradient bin may be tried in another order, so nearly every segment must be the same.
  const std::vector<std::string> files = test::sharedEurocImages();
  if (files.empty()) GTEST_SKIP() << "../shared/data not found: no real EuRoC frames to compare on";
  ASSERT_GE(files.size(), 10u);
  expectOpenCvsSegments(tenRealFrames(files));
}

TEST(LinearTimeLsd, FindsOpenCvsSegmentsOnSyntheticImages) {
  // As on the real frames, without ../shared, and with faint edges too.
  expectOpenCvsSegments(quadrilateralImages(10));
}

TEST(LinearTimeLsd, PyramidDownscaleFindsTheBlurredImagesLines) {
  // pyrDown's 5-tap kernel (sigma about 1 px) against the 1.2 px Gaussian and a resize: a
  // slightly sharper half image. Endpoints move along their lines (region growing stops
  // elsewhere), but most long segments must lie on the same lines.
  const std::vector<std::string> files = test::sharedEurocImages();
  if (files.empty()) GTEST_SKIP() << "../shared/data not found: no real EuRoC frames to compare on";
  ASSERT_GE(files.size(), 10u);
  const LineDetectorOptions o;
  LinearTimeLsd blurred(0.5, o.lsd_sigma_scale, o.lsd_quant);
  LinearTimeLsd pyramid(0.5, o.lsd_sigma_scale, o.lsd_quant, true);
  const Agreement n = compareOnImages(
      tenRealFrames(files),
      [&](const cv::Mat& image, std::vector<cv::Vec4f>* out) { blurred.detect(image, out); },
      [&](const cv::Mat& image, std::vector<cv::Vec4f>* out) { pyramid.detect(image, out); },
      hasCollinearCounterpart);
  std::cout << n.first_found << " of the blurred image's " << n.first << " segments found, "
            << n.second_found << " of the pyramid's " << n.second << "\n";
  ASSERT_GT(n.first, 500);
  EXPECT_GE(n.first_found, 0.8 * n.first);
  EXPECT_GE(n.second_found, 0.8 * n.second);
}

TEST(LinearTimeLsd, AnImageWithoutEdgesHasNoSegments) {
  LinearTimeLsd lsd(0.5, 0.6, 2.0);
  std::vector<cv::Vec4f> out{{1, 2, 3, 4}};
  lsd.detect(cv::Mat(kSize, CV_8UC1, cv::Scalar(90)), &out);
  EXPECT_TRUE(out.empty());
  lsd.detect(cv::Mat(1, 1, CV_8UC1, cv::Scalar(90)), &out);
  EXPECT_TRUE(out.empty());
}

TEST(LineDetector, RefinementNeedsOpenCvsLsd) {
  LineDetectorOptions o;
  o.lsd_refine = true;
  EXPECT_NE(test::errorOf([&] { o.validate("lines.detector"); }).find("lsd_refine"),
            std::string::npos);
  o.method = "opencv_lsd";
  EXPECT_NO_THROW(o.validate("lines.detector"));
}

TEST(LineDetector, PyramidDownscaleNeedsLsdAtHalfScale) {
  LineDetectorOptions o;
  o.lsd_pyramid_downscale = true;
  EXPECT_NO_THROW(o.validate("lines.detector"));
  o.lsd_scale = 0.6;
  EXPECT_NE(test::errorOf([&] { o.validate("lines.detector"); }).find("lsd_pyramid_downscale"),
            std::string::npos);
  o.lsd_scale = 0.5;
  o.method = "opencv_lsd";
  EXPECT_NE(test::errorOf([&] { o.validate("lines.detector"); }).find("lsd_pyramid_downscale"),
            std::string::npos);
}

TEST(LineDetector, FldOnAScaledImageReturnsFullResolutionSegments) {
  const test::SyntheticLineScene scene(kSize);
  const cv::Mat image = scene.render(kBars, {0, 0});
  std::vector<LineSegment> edges;
  for (const Bar& bar : kBars)
    for (const LineSegment& e : longEdges(bar, {0, 0})) edges.push_back(e);
  // Each long edge of a bar is found, as a segment within 2 px of it (FLD's Canny edges are
  // whole pixels: at half scale a pixel is 2 px of the full image) and at least half as long.
  for (double scale : {1.0, 0.5}) {
    LineDetectorOptions o;
    o.method = "fld";
    o.fld_scale = scale;
    const auto lines = LineDetector(o, kSize).detect(image);
    std::set<std::size_t> found;
    for (const LineSegment& s : lines)
      for (std::size_t k = 0; k < edges.size(); ++k)
        if (edges[k].distanceToLine(s.start) < 2.0 && edges[k].distanceToLine(s.end) < 2.0 &&
            s.length() > 0.5 * edges[k].length())
          found.insert(k);
    EXPECT_EQ(found.size(), edges.size()) << "fld_scale " << scale;
  }
}

TEST(LineTracker, TrackedLinesComeFirstUnderTheCap) {
  // With room for 6 lines, the second frame keeps the 6 tracked ones and starts none of the
  // new bar's longer edges.
  const test::SyntheticLineScene scene(kSize);
  LineTrackerOptions options;
  options.detector.max_lines = 6;
  for (const std::string type : {"flow", "descriptor"}) {
    options.tracker = type;
    const auto tracker = createLineTracker(test::undistortedCamera(), options);
    const LineFrame f1 = tracker->track(scene.render(kBars, {0, 0}), 0.0);
    ASSERT_EQ(f1.lines.size(), 6u) << type;
    std::vector<Bar> more = kBars;
    more.push_back({{680, 200}, {300, 40}, 90});  // longer than any other edge
    const LineFrame f2 = tracker->track(scene.render(more, {3, 2}), 0.05);
    EXPECT_EQ(f2.lines.size(), 6u) << type;
    EXPECT_EQ(f2.stats.tracked, 6) << type;
    EXPECT_EQ(f2.stats.new_lines, 0) << type;
  }
}

TEST(OpticalFlowLineTracker, Type1KeptLinesKeepTheirIds) {
  const test::SyntheticLineScene scene(kSize);
  OpticalFlowLineTracker tracker(test::undistortedCamera(), defaultOptions());
  const LineFrame f1 = tracker.track(scene.render(kBars, {0, 0}), 0.0);
  ASSERT_GE(f1.lines.size(), 10u);
  EXPECT_EQ(f1.stats.new_lines, static_cast<int>(f1.lines.size()));
  const cv::Point2d offsets[] = {{7.3, -4.6}, {13.9, -8.1}, {18.2, -14.7}};
  auto previous = byId(f1);
  for (int k = 0; k < 3; ++k) {
    const LineFrame f = tracker.track(scene.render(kBars, offsets[k]), 0.05 * (k + 1));
    EXPECT_EQ(f.stats.new_lines, 0) << "frame " << k + 2;
    EXPECT_EQ(f.stats.tracked, static_cast<int>(f1.lines.size())) << "frame " << k + 2;
    EXPECT_EQ(f.stats.merged, 0);
    EXPECT_EQ(f.stats.clipped, 0);
    const cv::Point2d step = offsets[k] - (k ? offsets[k - 1] : cv::Point2d(0, 0));
    for (const auto& [id, obs] : byId(f)) {
      ASSERT_TRUE(previous.count(id)) << "unknown id " << id;
      EXPECT_EQ(obs.track_count, k + 2);
      // The same edge: the previous observation moved by the scene's step is on this line.
      const LineObservation& before = previous.at(id);
      const Eigen::Vector2d d(step.x, step.y);
      const LineSegment moved(before.start_px + d, before.end_px + d);
      EXPECT_LT(segmentOf(obs).distanceToLine(moved.start), 1.5);
      EXPECT_LT(segmentOf(obs).distanceToLine(moved.end), 1.5);
      EXPECT_LT(angleDifference(segmentOf(obs).angle(), moved.angle()) * kRadToDeg, 2.0);
    }
    previous = byId(f);
  }
}

TEST(OpticalFlowLineTracker, DetectEveryOtherFrameCarriesLinesOnTheirFlow) {
  const test::SyntheticLineScene scene(kSize);
  LineTrackerOptions options = defaultOptions();
  options.flow.detect_every = 2;
  OpticalFlowLineTracker tracker(test::undistortedCamera(), options);
  const LineFrame f1 = tracker.track(scene.render(kBars, {0, 0}), 0.0);
  ASSERT_GE(f1.lines.size(), 10u);
  // A bar appears in frame 2, which is not detected: no new line before frame 3.
  std::vector<Bar> more = kBars;
  const Bar added{{680, 200}, {200, 40}, 90};
  more.push_back(added);
  const cv::Point2d o2(6.4, -3.9), o3(12.1, -7.5);
  const LineFrame f2 = tracker.track(scene.render(more, o2), 0.05);
  EXPECT_EQ(f2.stats.detected, 0);
  EXPECT_EQ(f2.stats.new_lines, 0);
  EXPECT_EQ(f2.stats.tracked, static_cast<int>(f1.lines.size()));
  const auto before = byId(f1);
  const Eigen::Vector2d d2(o2.x, o2.y);
  for (const auto& [id, obs] : byId(f2)) {
    ASSERT_TRUE(before.count(id)) << "unknown id " << id;
    EXPECT_EQ(obs.track_count, 2);
    // On the moved edge: the flow prediction alone is this frame's line.
    const LineSegment moved(before.at(id).start_px + d2, before.at(id).end_px + d2);
    EXPECT_LT(moved.distanceToLine(obs.start_px), 1.0) << "id " << id;
    EXPECT_LT(moved.distanceToLine(obs.end_px), 1.0) << "id " << id;
  }
  const LineFrame f3 = tracker.track(scene.render(more, o3), 0.10);
  EXPECT_GT(f3.stats.detected, 0);
  EXPECT_EQ(f3.stats.tracked, static_cast<int>(f1.lines.size()));
  EXPECT_EQ(f3.stats.new_lines, 2);
  for (const auto& obs : f3.lines)
    if (before.count(obs.id)) {
      EXPECT_EQ(obs.track_count, 3);
    }
}

TEST(OpticalFlowLineTracker, FlowThatLosesMostLinesMakesTheNextFrameDetect) {
  const test::SyntheticLineScene scene(kSize);
  LineTrackerOptions options = defaultOptions();
  options.flow.detect_every = 2;
  OpticalFlowLineTracker tracker(test::undistortedCamera(), options);
  ASSERT_GT(tracker.track(scene.render(kBars, {0, 0}), 0.0).stats.detected, 0);
  EXPECT_EQ(tracker.track(scene.render(kBars, {4, -2}), 0.05).stats.detected, 0);
  // The view changes completely: frame 3 detects on schedule, but its flow lost every line.
  const std::vector<Bar> elsewhere = {{{380, 240}, {300, 50}, 45}};
  ASSERT_GT(tracker.track(scene.render(elsewhere, {0, 0}), 0.10).stats.detected, 0);
  // So frame 4, which the schedule would skip, detects as well.
  EXPECT_GT(tracker.track(scene.render(elsewhere, {3, 2}), 0.15).stats.detected, 0);
  // Its flow kept the lines: frame 5 is skipped again.
  EXPECT_EQ(tracker.track(scene.render(elsewhere, {6, 4}), 0.20).stats.detected, 0);
}

TEST(OpticalFlowLineTracker, Type2NewLinesGetNewIds) {
  const test::SyntheticLineScene scene(kSize);
  OpticalFlowLineTracker tracker(test::undistortedCamera(), defaultOptions());
  const auto f1 = byId(tracker.track(scene.render(kBars, {0, 0}), 0.0));
  std::vector<Bar> more = kBars;
  const Bar added{{680, 200}, {200, 40}, 90};  // clear of the other bars
  more.push_back(added);
  const cv::Point2d offset(-5.5, 3.0);
  const LineFrame f2 = tracker.track(scene.render(more, offset), 0.05);
  EXPECT_EQ(f2.stats.new_lines, 2);
  EXPECT_EQ(f2.stats.tracked, static_cast<int>(f1.size()));
  int new_on_added = 0;
  for (const auto& obs : f2.lines) {
    if (f1.count(obs.id)) {
      EXPECT_EQ(obs.track_count, 2);
      continue;
    }
    EXPECT_EQ(obs.track_count, 1);
    const auto edges = longEdges(added, offset);
    new_on_added += onLine(obs, edges[0]) || onLine(obs, edges[1]);
  }
  EXPECT_EQ(new_on_added, 2);
}

TEST(OpticalFlowLineTracker, Type3SplitLineIsMergedUnderItsOldId) {
  const test::SyntheticLineScene scene(kSize);
  const std::vector<Bar> bar = {{{376, 240}, {500, 40}, 0}};
  OpticalFlowLineTracker tracker(test::undistortedCamera(), defaultOptions());
  const LineFrame f1 = tracker.track(scene.render(bar, {0, 0}), 0.0);
  ASSERT_EQ(f1.lines.size(), 2u);

  // Next frame: moved, and a 60 px square of background hides the bar's middle, so LSD finds
  // each long edge as two pieces of ~220 px.
  const cv::Point2d offset(5, 3);
  const cv::Mat split = scene.render(bar, offset, {Occluder{{376, 240}, 30}});
  LineDetector detector(LineDetectorOptions(), kSize);
  int pieces = 0;
  for (const auto& seg : detector.detect(split)) pieces += seg.length() >= detector.minLength();
  ASSERT_EQ(pieces, 4);

  const LineFrame f2 = tracker.track(split, 0.05);
  EXPECT_EQ(f2.stats.detected, 4);
  EXPECT_EQ(f2.stats.merged, 2);
  EXPECT_EQ(f2.stats.new_lines, 0);
  ASSERT_EQ(f2.lines.size(), 2u);
  const auto before = byId(f1);
  const auto edges = longEdges(bar[0], offset);
  for (const auto& obs : f2.lines) {
    ASSERT_TRUE(before.count(obs.id));
    EXPECT_TRUE(onLine(obs, edges[0]) || onLine(obs, edges[1]));
    // The merged segment spans both pieces: the whole edge as detected in the first frame,
    // moved by the offset (and oriented the same way).
    const LineObservation& whole = before.at(obs.id);
    EXPECT_NEAR(obs.start_px.x(), whole.start_px.x() + offset.x, 3.0);
    EXPECT_NEAR(obs.end_px.x(), whole.end_px.x() + offset.x, 3.0);
  }
}

TEST(OpticalFlowLineTracker, Type4LineLeavingTheImageKeepsItsId) {
  const test::SyntheticLineScene scene(kSize);
  const std::vector<Bar> bar = {{{560, 240}, {300, 40}, 0}};  // x from 410 to 710
  OpticalFlowLineTracker tracker(test::undistortedCamera(), defaultOptions());
  const LineFrame f1 = tracker.track(scene.render(bar, {0, 0}), 0.0);
  ASSERT_EQ(f1.lines.size(), 2u);
  const auto first = byId(f1);
  // Move right 25 px a frame: the right ends leave the image from the second step on.
  int clipped = 0;
  for (int k = 1; k <= 4; ++k) {
    const cv::Point2d offset(25.0 * k, 2.0 * k);
    const LineFrame f = tracker.track(scene.render(bar, offset), 0.05 * k);
    clipped += f.stats.clipped;
    EXPECT_EQ(f.stats.new_lines, 0) << "frame " << k;
    ASSERT_EQ(f.lines.size(), 2u) << "frame " << k;
    const auto edges = longEdges(bar[0], offset);
    for (const auto& obs : f.lines) {
      EXPECT_TRUE(first.count(obs.id)) << "frame " << k;
      EXPECT_EQ(obs.track_count, k + 1);
      EXPECT_TRUE(onLine(obs, edges[0]) || onLine(obs, edges[1]));
      if (710 + 25.0 * k > kSize.width) {
        EXPECT_GT(std::max(obs.start_px.x(), obs.end_px.x()), kSize.width - 6.0);
      }
    }
  }
  // Steps 2, 3 and 4 predict the right endpoints outside: 2 lines each.
  EXPECT_EQ(clipped, 6);
}

TEST(OpticalFlowLineTracker, PredictionClipsAlongTheSlope) {
  // A slanted bar moving up-right out of the image: a clipped prediction stays on the moved
  // edge's line and ends on the border.
  const test::SyntheticLineScene scene(kSize);
  const std::vector<Bar> bar = {{{600, 160}, {260, 40}, -30}};
  OpticalFlowLineTracker tracker(test::undistortedCamera(), defaultOptions());
  tracker.track(scene.render(bar, {0, 0}), 0.0);
  int clipped = 0;
  for (int k = 1; k <= 4; ++k) {
    const cv::Point2d offset(25.0 * k, -25.0 * k);
    tracker.track(scene.render(bar, offset), 0.05 * k);
    const auto edges = longEdges(bar[0], offset);
    for (const auto& p : tracker.lastPredictions()) {
      if (!p.valid || !p.clipped) continue;
      ++clipped;
      const double tol = 1.5;
      for (const Eigen::Vector2d& q : {p.segment.start, p.segment.end}) {
        EXPECT_TRUE(edges[0].distanceToLine(q) < tol || edges[1].distanceToLine(q) < tol)
            << "frame " << k << ": " << q.transpose();
        EXPECT_TRUE(q.x() >= 0 && q.y() >= 0 && q.x() <= kSize.width - 1 &&
                    q.y() <= kSize.height - 1);
      }
      const double x_max = std::max(p.segment.start.x(), p.segment.end.x());
      const double y_min = std::min(p.segment.start.y(), p.segment.end.y());
      EXPECT_TRUE(std::abs(x_max - (kSize.width - 1)) < 1e-9 || std::abs(y_min) < 1e-9);
    }
  }
  EXPECT_GE(clipped, 4);
}

TEST(DescriptorLineTracker, KeepsIdsOfTranslatedLines) {
  const test::SyntheticLineScene scene(kSize);
  DescriptorLineTracker tracker(test::undistortedCamera(), defaultOptions());
  const LineFrame f1 = tracker.track(scene.render(kBars, {0, 0}), 0.0);
  const cv::Point2d offset(7.3, -4.6);
  const LineFrame f2 = tracker.track(scene.render(kBars, offset), 0.05);
  const auto before = byId(f1);
  int kept = 0;
  for (const auto& [id, obs] : byId(f2)) {
    if (!before.count(id)) continue;
    ++kept;
    const Eigen::Vector2d d(offset.x, offset.y);
    EXPECT_LT(segmentOf(obs).distanceToLine(before.at(id).start_px + d), 2.0) << "wrong match";
  }
  EXPECT_GE(kept, static_cast<int>(0.8 * f1.lines.size()));
  EXPECT_EQ(f2.stats.tracked, kept);
  EXPECT_EQ(f2.stats.merged, 0);
}

TEST(DescriptorLineTracker, DoesNotMergeSplitLines) {
  // The baseline's known limitation: the pieces of a split line stay separate segments.
  const test::SyntheticLineScene scene(kSize);
  const std::vector<Bar> bar = {{{376, 240}, {500, 40}, 0}};
  DescriptorLineTracker tracker(test::undistortedCamera(), defaultOptions());
  tracker.track(scene.render(bar, {0, 0}), 0.0);
  const LineFrame f2 = tracker.track(scene.render(bar, {5, 3}, {Occluder{{376, 240}, 30}}), 0.05);
  EXPECT_EQ(f2.stats.merged, 0);
  EXPECT_EQ(f2.lines.size(), 4u);
  EXPECT_GE(f2.stats.new_lines, 2);
}

TEST(LineTracker, DistortedStraightEdgeComesOutStraightInNormalisedCoordinates) {
  // A straight bar in normalised coordinates, drawn through EuRoC's distortion (curved in the
  // raw image, bowed by several pixels near the top).
  const CameraOptions camera = Config::load(test::sourcePath("config/euroc.yaml")).camera;
  const auto model = CameraModel::create(camera);
  const Eigen::Vector2d a(-0.62, -0.40), b(0.58, -0.36);
  const Eigen::Vector2d u = (b - a).normalized(), n(-u.y(), u.x());
  const double half = 0.03;
  cv::Mat raw(kSize, CV_8UC1, cv::Scalar(150));
  constexpr int kShift = 4;
  std::vector<cv::Point> poly;
  auto add = [&](const Eigen::Vector2d& xy) {
    const Eigen::Vector2d px = model->distort(xy);
    poly.emplace_back(cvRound(px.x() * (1 << kShift)), cvRound(px.y() * (1 << kShift)));
  };
  for (int i = 0; i <= 100; ++i) add(a + (b - a) * (i / 100.0) + half * n);
  for (int i = 100; i >= 0; --i) add(a + (b - a) * (i / 100.0) - half * n);
  cv::fillPoly(raw, std::vector<std::vector<cv::Point>>{poly}, cv::Scalar(40), cv::LINE_AA, kShift);
  const Eigen::Vector2d mid_raw = model->distort(0.5 * (a + b) + half * n);
  const Eigen::Vector2d end_raw = model->distort(a + half * n);
  ASSERT_GT(std::abs(mid_raw.y() - end_raw.y()), 5.0) << "the edge should be visibly curved";

  OpticalFlowLineTracker tracker(camera, defaultOptions());
  const LineFrame f = tracker.track(raw, 0.0);
  // Each long edge of the bar: one long segment on the normalised edge line.
  // 2 px: the anti-aliased polygon fill and LSD each move an edge by up to about a pixel;
  // without undistortion the endpoints would be tens of pixels off this line.
  const double tol = 2.0 / camera.intrinsics[0];
  const double edge_length = (b - a).norm();
  int found = 0;
  for (const auto& obs : f.lines) {
    for (double side : {1.0, -1.0}) {
      const Eigen::Vector2d p0 = a + side * half * n;
      auto dist = [&](const Eigen::Vector2d& q) { return std::abs(n.dot(q - p0)); };
      if (dist(obs.start_norm) < tol && dist(obs.end_norm) < tol &&
          (obs.end_norm - obs.start_norm).norm() > 0.8 * edge_length)
        ++found;
    }
    // Pixel and normalised coordinates agree through K.
    EXPECT_NEAR(obs.start_norm.x(),
                (obs.start_px.x() - camera.intrinsics[2]) / camera.intrinsics[0], 1e-12);
  }
  EXPECT_EQ(found, 2);
}

TEST(ImageUndistorter, GivesCvRemapsImageBitForBitBorderIncluded) {
  // The reference: cv::remap with tables made from the camera model as the constructor makes
  // them. Three cameras: EuRoC's (every pinhole pixel has its four sources in the image), a
  // fisheye and a pincushion, whose pinhole corners map outside the raw image.
  CameraOptions euroc = Config::load(test::sourcePath("config/euroc.yaml")).camera;
  CameraOptions pincushion = euroc;
  pincushion.distortion_coefficients = {0.25, 0.05, 0.001, -0.002};
  CameraOptions fisheye = euroc;
  fisheye.distortion_model = "equidistant";
  fisheye.distortion_coefficients = {0.3, 0.1, -0.05, 0.01};
  cv::RNG rng(7);
  CameraOptions odd_size = euroc;  // 749 x 479 pixels: the last three past a group of eight
  odd_size.width = 749;
  odd_size.height = 479;
  std::vector<int> outside_sources;
  for (const CameraOptions& camera : {euroc, fisheye, pincushion, odd_size}) {
    const auto model = CameraModel::create(camera);
    const cv::Size size(camera.width, camera.height);
    cv::Mat map_x(size, CV_32FC1), map_y(size, CV_32FC1);
    for (int v = 0; v < size.height; ++v) {
      for (int u = 0; u < size.width; ++u) {
        const Eigen::Vector2d xy((u - camera.intrinsics[2]) / camera.intrinsics[0],
                                 (v - camera.intrinsics[3]) / camera.intrinsics[1]);
        const Eigen::Vector2d raw = model->distort(xy);
        map_x.at<float>(v, u) = static_cast<float>(raw.x());
        map_y.at<float>(v, u) = static_cast<float>(raw.y());
      }
    }
    cv::Mat map_xy, map_frac;
    cv::convertMaps(map_x, map_y, map_xy, map_frac, CV_16SC2);
    int outside = 0;
    for (int v = 0; v < size.height; ++v)
      for (int u = 0; u < size.width; ++u) {
        const cv::Vec2s s = map_xy.at<cv::Vec2s>(v, u);
        outside += s[0] < 0 || s[1] < 0 || s[0] >= size.width - 1 || s[1] >= size.height - 1;
      }
    outside_sources.push_back(outside);

    const ImageUndistorter undistorter(camera);
    cv::Mat noise(size, CV_8UC1), white(size, CV_8UC1, cv::Scalar(255));
    rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
    for (const cv::Mat& raw : {noise, white}) {
      cv::Mat expected;
      cv::remap(raw, expected, map_xy, map_frac, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                cv::Scalar(0));
      const cv::Mat got = undistorter.undistort(raw);
      ASSERT_EQ(got.size(), expected.size());
      EXPECT_EQ(cv::countNonZero(got != expected), 0)
          << camera.distortion_model << " " << camera.distortion_coefficients[0];
    }
  }
  EXPECT_EQ(outside_sources[0], 0);
  EXPECT_GT(outside_sources[2], 1000) << "the border path must be exercised";
}

TEST(LineTrackerOptions, LoadFromYamlAndNameBadKeys) {
  const auto yaml = YamlReader::fromString(
      "lines:\n  tracker: descriptor\n  detector: {max_lines: 25, lsd_scale: 0.8, lsd_quant: 4,\n"
      "    lsd_reference_brightness: 90, lsd_min_quant_scale: 0.5}\n"
      "  flow: {samples_per_line: 7, detect_every: 3}\n",
      "test.yaml");
  const LineTrackerOptions o = LineTrackerOptions::load(yaml, "lines");
  EXPECT_EQ(o.tracker, "descriptor");
  EXPECT_EQ(o.detector.max_lines, 25);
  EXPECT_DOUBLE_EQ(o.detector.lsd_scale, 0.8);
  EXPECT_DOUBLE_EQ(o.detector.lsd_quant, 4.0);
  EXPECT_DOUBLE_EQ(o.detector.lsd_reference_brightness, 90.0);
  EXPECT_DOUBLE_EQ(o.detector.lsd_min_quant_scale, 0.5);
  EXPECT_DOUBLE_EQ(o.detector.min_length_ratio, 0.06);
  EXPECT_EQ(o.flow.samples_per_line, 7);
  EXPECT_EQ(o.flow.detect_every, 3);
  EXPECT_TRUE(yaml.unknownKeys().empty());
  EXPECT_EQ(createLineTracker(test::undistortedCamera(), o)->name(), std::string("descriptor"));

  const auto bad = YamlReader::fromString("lines:\n  flow: {klt_window_px: 20}\n", "bad.yaml");
  try {
    LineTrackerOptions::load(bad, "lines");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("lines.flow.klt_window_px"), std::string::npos)
        << e.what();
  }
  const auto bad_every = YamlReader::fromString("lines:\n  flow: {detect_every: 0}\n", "e.yaml");
  const std::string every_error =
      test::errorOf([&] { LineTrackerOptions::load(bad_every, "lines"); });
  EXPECT_NE(every_error.find("lines.flow.detect_every"), std::string::npos) << every_error;
  const auto bad_quant = YamlReader::fromString("lines:\n  detector: {lsd_quant: 0}\n", "q.yaml");
  EXPECT_THROW(LineTrackerOptions::load(bad_quant, "lines"), Error);
  const auto bad_tracker = YamlReader::fromString("lines:\n  tracker: magic\n", "t.yaml");
  EXPECT_THROW(LineTrackerOptions::load(bad_tracker, "lines"), Error);
}

TEST(LineTracker, EurocFramesAreDetectedAndTracked) {
  ALVIO_REQUIRE_SHARED_DATA(data);
  const std::string dir = data + "/euroc_V1_01_easy_10frames_chutsu/frontend/cam0";
  if (!std::filesystem::is_directory(dir)) GTEST_SKIP() << dir << " not found";
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(dir)) files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  ASSERT_EQ(files.size(), 10u);
  const CameraOptions camera = Config::load(test::sourcePath("config/euroc.yaml")).camera;
  for (const std::string type : {"flow", "descriptor"}) {
    LineTrackerOptions options;
    options.tracker = type;
    const auto tracker = createLineTracker(camera, options);
    int lines = 0, continued = 0, previous = 0;
    for (std::size_t k = 0; k < files.size(); ++k) {
      const cv::Mat gray = cv::imread(files[k], cv::IMREAD_GRAYSCALE);
      ASSERT_FALSE(gray.empty()) << files[k];
      const LineFrame f = tracker->track(gray, 0.05 * k);
      byId(f);  // no duplicate IDs
      EXPECT_EQ(f.stats.tracked + f.stats.new_lines, static_cast<int>(f.lines.size()));
      if (k > 0) {
        lines += f.lines.size();
        continued += f.stats.tracked;
        EXPECT_LE(f.stats.tracked, previous);
      }
      previous = f.lines.size();
    }
    // A slow flight at 20 Hz: most lines continue from one frame to the next.
    EXPECT_GE(lines / 9, 25) << type;
    EXPECT_GE(continued, 0.5 * lines) << type;
  }
}

TEST(LineTrackerOptions, ShippedConfigHasTheLinesSection) {
  const YamlReader yaml(test::sourcePath("config/euroc.yaml"));
  const Config config = Config::load(test::sourcePath("config/euroc.yaml"));
  EXPECT_EQ(config.lines.tracker, "flow");
  EXPECT_EQ(config.lines.detector.max_lines, 60);
  EXPECT_EQ(config.lines.flow.samples_per_line, 5);
  // Every key of the section is read.
  LineTrackerOptions::load(yaml, "lines");
  for (const auto& key : yaml.unknownKeys()) EXPECT_NE(key.rfind("lines", 0), 0u) << key;
}
