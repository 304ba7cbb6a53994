// KLT started where the gyroscope's rotation moves each feature: the rotation between two
// frames (GyroRotation, checked against the geometry of a camera turning in the world), and
// both trackers following a turn too fast for one pyramid level once they are given it, and the
// configured corner tracker a turn too fast for all of them.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <limits>
#include <map>
#include <opencv2/imgproc.hpp>

#include "alvio/camera/camera_model.h"
#include "alvio/common/rotation.h"
#include "alvio/config/config.h"
#include "alvio/frontend/gyro_rotation.h"
#include "alvio/frontend/point_tracker.h"
#include "alvio/frontend/rotated_pixels.h"
#include "alvio/lines/optical_flow_line_tracker.h"
#include "synthetic_line_scene.h"
#include "test_images.h"
#include "test_support.h"

using namespace alvio;

namespace {
constexpr int64_t kSecond = 1'000'000'000;

// The camera as mounted on EuRoC's body: about 90 degrees about the body's z axis.
Eigen::Matrix3d eurocCameraInBody() {
  const Config config = Config::load(test::sourcePath("config/euroc.yaml"));
  return config.camera.T_b_c.linear();
}

// Body orientation in the world at time t for a rate w(t) = w0 + w1 t about a fixed axis.
Eigen::Matrix3d bodyAt(const Eigen::Vector3d& axis, double w0, double w1, double t) {
  return expQuaternion(axis * (w0 * t + 0.5 * w1 * t * t)).toRotationMatrix();
}

GyroRotation gyroscope(const Eigen::Matrix3d& R_b_c, const Eigen::Vector3d& axis, double w0,
                       double w1, int64_t from_ns, int64_t to_ns) {
  GyroRotation gyro(R_b_c);
  for (int64_t t = from_ns; t <= to_ns; t += 5'000'000) {  // 200 Hz
    ImuSample s;
    s.t_ns = t;
    s.gyr = axis * (w0 + w1 * (t * 1e-9));
    gyro.add(s);
  }
  return gyro;
}

// The image the camera sees after turning by R_c1_c0, for a scene far away (a homography).
cv::Mat turned(const cv::Mat& image, const CameraModel& camera, const Eigen::Matrix3d& R_c1_c0) {
  Eigen::Matrix3d K;
  K << camera.fx(), 0, camera.cx(), 0, camera.fy(), camera.cy(), 0, 0, 1;
  const Eigen::Matrix3d H = K * R_c1_c0 * K.inverse();
  cv::Mat Hcv(3, 3, CV_64F), out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Hcv.at<double>(r, c) = H(r, c);
  cv::warpPerspective(image, out, Hcv, image.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return out;
}

Eigen::Vector2d turnedPixel(const CameraModel& camera, const Eigen::Matrix3d& R_c1_c0,
                            const Eigen::Vector2d& px) {
  Eigen::Vector2d out;
  EXPECT_TRUE(camera.project(R_c1_c0 * camera.backProject(px), &out));
  return out;
}

// A turn of 0.1 rad, the image moving about 45 px diagonally: out of reach of KLT on one
// pyramid level (21 px windows for corners, 15 px for lines) without a prediction.
Eigen::Matrix3d fastTurn() {
  return Eigen::AngleAxisd(0.1, Eigen::Vector3d(1.0, 1.0, 0.1).normalized()).toRotationMatrix();
}
}  // namespace

TEST(GyroRotation, MapsWhatTheCameraSawIntoWhereItSeesItAfterTurning) {
  const Eigen::Matrix3d R_b_c = eurocCameraInBody();
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  const double w0 = 0.7, w1 = 4.0;  // rad/s and rad/s^2: the rate ramps up
  const GyroRotation gyro = gyroscope(R_b_c, axis, w0, w1, 0, kSecond);
  // Between sample times, so that both ends interpolate the rate.
  const int64_t t0 = 402'500'000, t1 = 451'200'000;
  const auto R_c1_c0 = gyro.cameraRotation(t0, t1);
  ASSERT_TRUE(R_c1_c0.has_value());
  const Eigen::Vector3d p_w(2.0, -1.0, 4.0);  // a point in the world, seen from the origin
  auto seen = [&](int64_t t) {
    const Eigen::Matrix3d R_w_c = bodyAt(axis, w0, w1, t * 1e-9) * R_b_c;
    return Eigen::Vector3d(R_w_c.transpose() * p_w);
  };
  // A rate linear in time about one axis integrates exactly.
  EXPECT_LT((*R_c1_c0 * seen(t0) - seen(t1)).norm(), 1e-9 * p_w.norm());
  EXPECT_GT((seen(t0) - seen(t1)).norm(), 0.1) << "the camera did turn";
}

TEST(GyroRotation, NothingUnlessTheSamplesReachBothTimes) {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  GyroRotation gyro = gyroscope(Eigen::Matrix3d::Identity(), z, 1.0, 0.0, 100'000'000, 200'000'000);
  EXPECT_FALSE(gyro.cameraRotation(99'000'000, 150'000'000).has_value());
  EXPECT_FALSE(gyro.cameraRotation(150'000'000, 201'000'000).has_value());
  ASSERT_TRUE(gyro.cameraRotation(100'000'000, 200'000'000).has_value());
  EXPECT_TRUE(gyro.cameraRotation(150'000'000, 150'000'000)->isIdentity(1e-15));
  // Dropping what an interval from 160 ms on no longer needs keeps that interval whole.
  const Eigen::Matrix3d before = *gyro.cameraRotation(160'000'000, 190'000'000);
  gyro.dropBefore(160'000'000);
  EXPECT_LE(gyro.size(), 10u);
  ASSERT_TRUE(gyro.cameraRotation(160'000'000, 190'000'000).has_value());
  EXPECT_TRUE(gyro.cameraRotation(160'000'000, 190'000'000)->isApprox(before, 1e-15));
  EXPECT_FALSE(gyro.cameraRotation(150'000'000, 190'000'000).has_value());
}

TEST(GyroRotation, SkipsSamplesWithNaNOrInfiniteRates) {
  // The faults suite's corrupted IMU: one sample in three NaN or infinite. The rate is
  // constant, so the samples left integrate it exactly.
  const Eigen::Vector3d w(0.4, -1.1, 0.7);
  GyroRotation gyro(Eigen::Matrix3d::Identity());
  const double bad[] = {std::numeric_limits<double>::quiet_NaN(),
                        std::numeric_limits<double>::infinity()};
  for (int k = 0; k <= 40; ++k) {
    ImuSample s;
    s.t_ns = k * 5'000'000;
    s.gyr = w;
    if (k % 3 == 1) s.gyr.y() = bad[(k / 3) % 2];
    gyro.add(s);
  }
  EXPECT_EQ(gyro.size(), 27u);
  const auto R_c1_c0 = gyro.cameraRotation(20'000'000, 170'000'000);
  ASSERT_TRUE(R_c1_c0.has_value());
  ASSERT_TRUE(R_c1_c0->allFinite());
  const Eigen::Matrix3d R_c0_c1 =
      Eigen::AngleAxisd(w.norm() * 0.15, w.normalized()).toRotationMatrix();
  EXPECT_TRUE(R_c1_c0->isApprox(R_c0_c1.transpose(), 1e-12));
}

TEST(RotatedPixels, MovesPixelsAsTheRotationDoesAndKeepsThoseTurnedBehind) {
  // A pinhole camera (f 400, centre (320, 240)): turned 30 degrees about its optical axis a
  // pixel turns about the centre; turned 120 degrees about x, a point ahead goes behind.
  const double f = 400, cx = 320, cy = 240;
  const auto bearing = [&](const Eigen::Vector2d& p) -> Eigen::Vector3d {
    return Eigen::Vector3d((p.x() - cx) / f, (p.y() - cy) / f, 1.0);
  };
  const auto project = [&](const Eigen::Vector3d& r, Eigen::Vector2d* out) {
    if (r.z() <= 0) return false;
    *out = Eigen::Vector2d(f * r.x() / r.z() + cx, f * r.y() / r.z() + cy);
    return true;
  };
  const double a = 30.0 * M_PI / 180.0;
  const Eigen::Matrix3d roll = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const std::vector<cv::Point2f> px{{420, 240}, {320, 140}, {320, 240}};
  const std::vector<cv::Point2f> moved = rotatedPixels(roll, px, bearing, project);
  ASSERT_EQ(moved.size(), px.size());
  EXPECT_NEAR(moved[0].x, 320 + 100 * std::cos(a), 1e-3);
  EXPECT_NEAR(moved[0].y, 240 + 100 * std::sin(a), 1e-3);
  EXPECT_NEAR(moved[1].x, 320 + 100 * std::sin(a), 1e-3);
  EXPECT_NEAR(moved[1].y, 240 - 100 * std::cos(a), 1e-3);
  EXPECT_NEAR(moved[2].x, 320, 1e-4);
  EXPECT_NEAR(moved[2].y, 240, 1e-4);
  const Eigen::Matrix3d over =
      Eigen::AngleAxisd(120.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const std::vector<cv::Point2f> behind = rotatedPixels(over, px, bearing, project);
  for (std::size_t i = 0; i < px.size(); ++i) {
    EXPECT_EQ(behind[i].x, px[i].x);
    EXPECT_EQ(behind[i].y, px[i].y);
  }
}

namespace {
// Corners a tracker with `options` found in `image` and tracks correctly (within 1.5 px) into
// the view after the turn R, given the turn or not; and how many stay in view.
struct KeptCorners {
  int correct = 0, visible = 0;
};
KeptCorners cornersKeptThroughTurn(const PointTrackerOptions& options,
                                   const std::shared_ptr<const CameraModel>& camera,
                                   const cv::Mat& image, const Eigen::Matrix3d& R,
                                   bool with_rotation) {
  PointTracker tracker(options, camera);
  const FeatureFrame f1 = tracker.track(image, 0);
  std::map<int, Eigen::Vector2d> first;
  for (const PointObservation& o : f1.points) first[o.id] = o.px;
  const FeatureFrame f2 =
      tracker.track(turned(image, *camera, R), 50'000'000, nullptr, -1,
                    with_rotation ? std::optional<Eigen::Matrix3d>(R) : std::nullopt);
  KeptCorners kept;
  for (const auto& [id, px] : first)  // the turn takes some out of the image
    kept.visible += camera->inImage(turnedPixel(*camera, R, px), 10.0);
  for (const PointObservation& o : f2.points) {
    const auto it = first.find(o.id);
    // KLT's windows only shift, while the turn also shears them a little: up to 1.4 px here.
    if (it != first.end() && (o.px - turnedPixel(*camera, R, it->second)).norm() < 1.5)
      ++kept.correct;
  }
  return kept;
}
}  // namespace

TEST(PointTracker, TheGyroscopesRotationCarriesCornersThroughAFastTurn) {
  const Config config = Config::load(test::sourcePath("config/euroc.yaml"));
  const std::shared_ptr<const CameraModel> camera = CameraModel::create(test::undistortedCamera());
  const cv::Mat texture =
      test::stretched(test::blurredNoise(cv::Size(camera->width(), camera->height()), 11, 3.0));
  PointTrackerOptions options = config.points;
  options.gyro_flow = true;
  options.klt_levels = 0;  // one level with or without the rotation
  options.gyro_klt_levels = 0;
  const KeptCorners with = cornersKeptThroughTurn(options, camera, texture, fastTurn(), true);
  const KeptCorners without = cornersKeptThroughTurn(options, camera, texture, fastTurn(), false);
  ASSERT_GE(with.visible, config.points.max_features / 2);
  EXPECT_EQ(without.visible, with.visible);
  EXPECT_GE(with.correct, with.visible * 9 / 10) << "of " << with.visible;
  EXPECT_LT(without.correct, with.visible / 4) << "of " << with.visible;
}

// The configured tracker, on all its pyramid levels: the corridor rendering turns its corners
// by 27 px a frame (median; 47 px at the 99th percentile), and fastTurn()'s 45 px are beyond
// plain pyramidal KLT (4 of 124 corners kept) but not beyond KLT started by the gyroscope.
TEST(PointTracker, TheConfiguredTrackerKeepsCornersThroughATurnBeyondPlainKlt) {
  const Config config = Config::load(test::sourcePath("config/euroc.yaml"));
  const std::shared_ptr<const CameraModel> camera = CameraModel::create(test::undistortedCamera());
  const cv::Mat texture =
      test::stretched(test::blurredNoise(cv::Size(camera->width(), camera->height()), 11, 3.0));
  const KeptCorners with = cornersKeptThroughTurn(config.points, camera, texture, fastTurn(), true);
  const KeptCorners without =
      cornersKeptThroughTurn(config.points, camera, texture, fastTurn(), false);
  ASSERT_GE(with.visible, config.points.max_features / 2);
  EXPECT_GE(with.correct, with.visible * 9 / 10) << "of " << with.visible;
  EXPECT_LT(without.correct, with.visible / 4) << "of " << with.visible;
}

TEST(OpticalFlowLineTracker, TheGyroscopesRotationCarriesLinesThroughAFastTurn) {
  const cv::Size size(752, 480);
  const test::SyntheticLineScene scene(size);
  const std::vector<test::Bar> bars = {{{230, 150}, {220, 40}, 0},
                                       {{500, 150}, {180, 36}, 60},
                                       {{300, 350}, {260, 44}, -20},
                                       {{540, 340}, {140, 70}, 10}};
  const cv::Mat image = scene.render(bars, {0, 0});
  const std::shared_ptr<const CameraModel> camera = CameraModel::create(test::undistortedCamera());
  const Eigen::Matrix3d R = fastTurn();
  const cv::Mat second = turned(image, *camera, R);

  auto keptLines = [&](bool with_rotation) {
    LineTrackerOptions options;
    options.flow.gyro_flow = true;
    options.flow.detect_every = 1;
    options.flow.klt_pyramid_levels = 0;
    options.flow.gyro_klt_levels = 0;
    OpticalFlowLineTracker tracker(test::undistortedCamera(), options);
    const LineFrame f1 = tracker.track(image, 0.0);
    std::map<int, LineObservation> first;
    for (const LineObservation& o : f1.lines) first[o.id] = o;
    const LineFrame f2 = tracker.track(
        second, 0.05, with_rotation ? std::optional<Eigen::Matrix3d>(R) : std::nullopt);
    int kept = 0;
    for (const LineObservation& o : f2.lines) {
      const auto it = first.find(o.id);
      if (it == first.end()) continue;
      // Still the same edge: the first frame's endpoints, turned, lie on this line.
      const LineSegment now(o.start_px, o.end_px);
      kept += now.distanceToLine(turnedPixel(*camera, R, it->second.start_px)) < 1.5 &&
              now.distanceToLine(turnedPixel(*camera, R, it->second.end_px)) < 1.5;
    }
    return std::make_pair(kept, static_cast<int>(first.size()));
  };
  const auto [with, lines] = keptLines(true);
  const auto [without, lines_again] = keptLines(false);
  ASSERT_GE(lines, 8);
  EXPECT_EQ(lines_again, lines);
  EXPECT_GE(with, lines - 1) << "of " << lines;
  EXPECT_LT(without, lines / 2) << "of " << lines;
}
