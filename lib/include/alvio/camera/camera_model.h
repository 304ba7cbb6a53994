#pragma once
// Camera projection models. Pixel coordinates have (0,0) at the centre of the
// top-left pixel. "Normalised" coordinates are (x/z, y/z) of the undistorted ray.

#include <Eigen/Core>
#include <memory>

#include "alvio/config/sensor_options.h"

namespace alvio {

class CameraModel {
 public:
  virtual ~CameraModel() = default;

  int width() const { return width_; }
  int height() const { return height_; }
  double fx() const { return fx_; }
  double fy() const { return fy_; }
  double cx() const { return cx_; }
  double cy() const { return cy_; }
  bool inImage(const Eigen::Vector2d& px, double border = 0.0) const {
    return px.x() >= border && px.y() >= border && px.x() <= width_ - 1 - border &&
           px.y() <= height_ - 1 - border;
  }

  /// Distort a normalised point and map it to pixels.
  virtual Eigen::Vector2d distort(const Eigen::Vector2d& xy) const = 0;
  /// Inverse of distort(): pixel to normalised undistorted point, iterated to 1e-10 accuracy.
  virtual Eigen::Vector2d undistort(const Eigen::Vector2d& px) const = 0;

  /// Project a camera-frame point; false if it is behind the camera.
  bool project(const Eigen::Vector3d& p_c, Eigen::Vector2d* px) const;
  /// Unit-depth ray (x, y, 1) through pixel `px`.
  Eigen::Vector3d backProject(const Eigen::Vector2d& px) const;

  /// Build the model described by the options (radial-tangential, equidistant or none).
  static std::unique_ptr<CameraModel> create(const CameraOptions& options);

 protected:
  CameraModel(int width, int height, double fx, double fy, double cx, double cy)
      : width_(width), height_(height), fx_(fx), fy_(fy), cx_(cx), cy_(cy) {}
  Eigen::Vector2d toPixel(const Eigen::Vector2d& xy_distorted) const {
    return {fx_ * xy_distorted.x() + cx_, fy_ * xy_distorted.y() + cy_};
  }
  Eigen::Vector2d fromPixel(const Eigen::Vector2d& px) const {
    return {(px.x() - cx_) / fx_, (px.y() - cy_) / fy_};
  }

 private:
  int width_, height_;
  double fx_, fy_, cx_, cy_;
};

/// Pinhole with radial-tangential (Brown-Conrady, OpenCV k1 k2 p1 p2 [k3]) distortion.
class PinholeRadtanCamera : public CameraModel {
 public:
  PinholeRadtanCamera(int width, int height, double fx, double fy, double cx, double cy, double k1,
                      double k2, double p1, double p2, double k3 = 0.0);
  Eigen::Vector2d distort(const Eigen::Vector2d& xy) const override;
  Eigen::Vector2d undistort(const Eigen::Vector2d& px) const override;
  /// Distortion of a normalised point and its 2x2 Jacobian (used by undistort's Newton steps).
  Eigen::Vector2d distortNormalized(const Eigen::Vector2d& xy, Eigen::Matrix2d* J) const;

 private:
  double k1_, k2_, p1_, p2_, k3_;
};

/// Pinhole with equidistant (Kannala-Brandt, OpenCV fisheye k1..k4) distortion.
class EquidistantCamera : public CameraModel {
 public:
  EquidistantCamera(int width, int height, double fx, double fy, double cx, double cy, double k1,
                    double k2, double k3, double k4);
  Eigen::Vector2d distort(const Eigen::Vector2d& xy) const override;
  Eigen::Vector2d undistort(const Eigen::Vector2d& px) const override;

 private:
  double k1_, k2_, k3_, k4_;
};

}  // namespace alvio
