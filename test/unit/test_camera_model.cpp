#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>

#include "alvio/camera/camera_model.h"
#include "alvio/config/config.h"
#include "test_support.h"

using namespace alvio;

namespace {
CameraOptions eurocCamera() {
  return Config::load(test::sourcePath("config/euroc.yaml")).camera;
}

CameraOptions fisheyeCamera() {
  CameraOptions o;
  o.distortion_model = "equidistant";
  o.width = 640;
  o.height = 480;
  o.intrinsics = {190.97, 190.97, 254.93, 256.89};  // a TUM-VI-like fisheye
  o.distortion_coefficients = {0.0034823894022493434, 0.0007150348452162257, -0.0020532361418706202,
                               0.00020293673591811182};
  return o;
}

// Pixels within `max_radius_px` of the principal point (a fisheye's corners see
// nothing) must survive back-projection and projection.
void expectRoundTrip(const CameraModel& cam, double tol_px, double max_radius_px = 1e9) {
  double worst = 0;
  for (double v = 0; v <= cam.height() - 1; v += 7.5) {
    for (double u = 0; u <= cam.width() - 1; u += 7.5) {
      const Eigen::Vector2d px(u, v);
      if ((px - Eigen::Vector2d(cam.cx(), cam.cy())).norm() > max_radius_px) continue;
      const Eigen::Vector3d ray = cam.backProject(px);
      Eigen::Vector2d back;
      ASSERT_TRUE(cam.project(ray * 3.7, &back));
      worst = std::max(worst, (back - px).norm());
    }
  }
  EXPECT_LT(worst, tol_px);
}
}  // namespace

TEST(CameraModel, RadtanRoundTripOverWholeImage) {
  expectRoundTrip(*CameraModel::create(eurocCamera()), 1e-6);
}

TEST(CameraModel, EquidistantRoundTripOverWholeImage) {
  // 240 px at f = 191 px is a 72 degree half-angle.
  expectRoundTrip(*CameraModel::create(fisheyeCamera()), 1e-6, 240.0);
}

TEST(CameraModel, RadtanMatchesOpenCv) {
  const CameraOptions o = eurocCamera();
  const auto cam = CameraModel::create(o);
  const cv::Matx33d K(o.intrinsics[0], 0, o.intrinsics[2], 0, o.intrinsics[1], o.intrinsics[3], 0,
                      0, 1);
  std::vector<cv::Point3d> pts;
  for (double x = -0.7; x <= 0.7; x += 0.1)
    for (double y = -0.5; y <= 0.5; y += 0.1) pts.emplace_back(x, y, 1.0);
  std::vector<cv::Point2d> cv_px;
  cv::projectPoints(pts, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, o.distortion_coefficients,
                    cv_px);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    Eigen::Vector2d px;
    ASSERT_TRUE(cam->project({pts[i].x, pts[i].y, pts[i].z}, &px));
    EXPECT_NEAR(px.x(), cv_px[i].x, 1e-9);
    EXPECT_NEAR(px.y(), cv_px[i].y, 1e-9);
  }
}

TEST(CameraModel, EquidistantMatchesOpenCvFisheye) {
  const CameraOptions o = fisheyeCamera();
  const auto cam = CameraModel::create(o);
  const cv::Matx33d K(o.intrinsics[0], 0, o.intrinsics[2], 0, o.intrinsics[1], o.intrinsics[3], 0,
                      0, 1);
  std::vector<cv::Point3d> pts;
  for (double x = -1.5; x <= 1.5; x += 0.25)
    for (double y = -1.5; y <= 1.5; y += 0.25) pts.emplace_back(x, y, 1.0);
  std::vector<cv::Point2d> cv_px;
  cv::fisheye::projectPoints(pts, cv_px, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K,
                             cv::Vec4d(o.distortion_coefficients.data()));
  for (std::size_t i = 0; i < pts.size(); ++i) {
    Eigen::Vector2d px;
    ASSERT_TRUE(cam->project({pts[i].x, pts[i].y, pts[i].z}, &px));
    EXPECT_NEAR(px.x(), cv_px[i].x, 1e-6);
    EXPECT_NEAR(px.y(), cv_px[i].y, 1e-6);
  }
}

TEST(CameraModel, PointsBehindTheCameraDoNotProject) {
  const auto cam = CameraModel::create(eurocCamera());
  Eigen::Vector2d px;
  EXPECT_FALSE(cam->project({0.1, 0.2, -1.0}, &px));
  EXPECT_FALSE(cam->project({0.1, 0.2, 0.0}, &px));
}

TEST(CameraModel, UndistortAgreesWithOpenCv) {
  const CameraOptions o = eurocCamera();
  const auto cam = CameraModel::create(o);
  const cv::Matx33d K(o.intrinsics[0], 0, o.intrinsics[2], 0, o.intrinsics[1], o.intrinsics[3], 0,
                      0, 1);
  std::vector<cv::Point2d> px = {{10, 10}, {367, 248}, {700, 450}, {100, 400}}, xy;
  cv::undistortPoints(
      px, xy, K, o.distortion_coefficients, cv::noArray(), cv::noArray(),
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-14));
  for (std::size_t i = 0; i < px.size(); ++i) {
    const Eigen::Vector2d u = cam->undistort({px[i].x, px[i].y});
    EXPECT_NEAR(u.x(), xy[i].x, 1e-6);
    EXPECT_NEAR(u.y(), xy[i].y, 1e-6);
  }
}
