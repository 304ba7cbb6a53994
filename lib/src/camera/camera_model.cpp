#include "alvio/camera/camera_model.h"

#include <cmath>

#include "alvio/common/error.h"

namespace alvio {

bool CameraModel::project(const Eigen::Vector3d& p_c, Eigen::Vector2d* px) const {
  if (p_c.z() <= 1e-9) return false;
  *px = distort(p_c.head<2>() / p_c.z());
  return true;
}

Eigen::Vector3d CameraModel::backProject(const Eigen::Vector2d& px) const {
  const Eigen::Vector2d xy = undistort(px);
  return {xy.x(), xy.y(), 1.0};
}

std::unique_ptr<CameraModel> CameraModel::create(const CameraOptions& o) {
  o.validate("camera");
  const auto& k = o.intrinsics;
  const auto& d = o.distortion_coefficients;
  if (o.distortion_model == "equidistant")
    return std::make_unique<EquidistantCamera>(o.width, o.height, k[0], k[1], k[2], k[3], d[0],
                                               d[1], d[2], d[3]);
  if (o.distortion_model == "none")
    return std::make_unique<PinholeRadtanCamera>(o.width, o.height, k[0], k[1], k[2], k[3], 0, 0, 0,
                                                 0);
  return std::make_unique<PinholeRadtanCamera>(o.width, o.height, k[0], k[1], k[2], k[3], d[0],
                                               d[1], d[2], d[3], d.size() > 4 ? d[4] : 0.0);
}

PinholeRadtanCamera::PinholeRadtanCamera(int width, int height, double fx, double fy, double cx,
                                         double cy, double k1, double k2, double p1, double p2,
                                         double k3)
    : CameraModel(width, height, fx, fy, cx, cy), k1_(k1), k2_(k2), p1_(p1), p2_(p2), k3_(k3) {}

Eigen::Vector2d PinholeRadtanCamera::distortNormalized(const Eigen::Vector2d& xy,
                                                       Eigen::Matrix2d* J) const {
  const double x = xy.x(), y = xy.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (k1_ + r2 * (k2_ + r2 * k3_));
  const Eigen::Vector2d out(x * radial + 2 * p1_ * x * y + p2_ * (r2 + 2 * x * x),
                            y * radial + p1_ * (r2 + 2 * y * y) + 2 * p2_ * x * y);
  if (J) {
    const double dradial_dr2 = k1_ + r2 * (2 * k2_ + 3 * r2 * k3_);
    (*J)(0, 0) = radial + 2 * x * x * dradial_dr2 + 2 * p1_ * y + 6 * p2_ * x;
    (*J)(0, 1) = 2 * x * y * dradial_dr2 + 2 * p1_ * x + 2 * p2_ * y;
    (*J)(1, 0) = 2 * x * y * dradial_dr2 + 2 * p1_ * x + 2 * p2_ * y;
    (*J)(1, 1) = radial + 2 * y * y * dradial_dr2 + 6 * p1_ * y + 2 * p2_ * x;
  }
  return out;
}

Eigen::Vector2d PinholeRadtanCamera::distort(const Eigen::Vector2d& xy) const {
  return toPixel(distortNormalized(xy, nullptr));
}

Eigen::Vector2d PinholeRadtanCamera::undistort(const Eigen::Vector2d& px) const {
  const Eigen::Vector2d target = fromPixel(px);
  Eigen::Vector2d xy = target;
  // Newton's method on distort(xy) = target; converges in a few steps inside the image.
  for (int it = 0; it < 30; ++it) {
    Eigen::Matrix2d J;
    const Eigen::Vector2d err = distortNormalized(xy, &J) - target;
    if (err.squaredNorm() < 1e-26) break;
    xy -= J.inverse() * err;
  }
  return xy;
}

EquidistantCamera::EquidistantCamera(int width, int height, double fx, double fy, double cx,
                                     double cy, double k1, double k2, double k3, double k4)
    : CameraModel(width, height, fx, fy, cx, cy), k1_(k1), k2_(k2), k3_(k3), k4_(k4) {}

Eigen::Vector2d EquidistantCamera::distort(const Eigen::Vector2d& xy) const {
  const double r = xy.norm();
  if (r < 1e-12) return toPixel(xy);
  const double theta = std::atan(r);
  const double t2 = theta * theta;
  const double theta_d = theta * (1 + t2 * (k1_ + t2 * (k2_ + t2 * (k3_ + t2 * k4_))));
  return toPixel(xy * (theta_d / r));
}

Eigen::Vector2d EquidistantCamera::undistort(const Eigen::Vector2d& px) const {
  const Eigen::Vector2d xy_d = fromPixel(px);
  const double theta_d = xy_d.norm();
  if (theta_d < 1e-12) return xy_d;
  // Newton on f(theta) = theta (1 + k1 t^2 + ...) - theta_d.
  double theta = theta_d;
  for (int it = 0; it < 30; ++it) {
    const double t2 = theta * theta;
    const double f = theta * (1 + t2 * (k1_ + t2 * (k2_ + t2 * (k3_ + t2 * k4_)))) - theta_d;
    const double df = 1 + t2 * (3 * k1_ + t2 * (5 * k2_ + t2 * (7 * k3_ + t2 * 9 * k4_)));
    const double step = f / df;
    theta -= step;
    if (std::abs(step) < 1e-14) break;
  }
  return xy_d * (std::tan(theta) / theta_d);
}

}  // namespace alvio
