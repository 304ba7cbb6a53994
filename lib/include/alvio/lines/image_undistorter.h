#pragma once
// Undistorts whole images to an ideal pinhole image with the camera's own K. Lines are
// detected and tracked on that image: EuRoC's radial distortion (k1 = -0.28) bends straight
// edges by several pixels near the border, which splits or shortens LSD segments, while in the
// pinhole image a straight 3D edge is a straight segment whose endpoints map to undistorted
// normalised coordinates by K^-1 alone. The remap tables are computed once, from the project's
// own CameraModel, so every distortion model it supports is handled the same way.

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "alvio/config/sensor_options.h"

namespace alvio {

class ImageUndistorter {
 public:
  explicit ImageUndistorter(const CameraOptions& camera);

  /// The pinhole image (bilinear), bit for bit what cv::remap gives with the fixed-point
  /// tables of cv::convertMaps and a black border. Without distortion the input is returned as
  /// is (no copy).
  cv::Mat undistort(const cv::Mat& raw) const;
  /// 255 where the pinhole pixel has a source pixel in the raw image, 0 elsewhere (CV_8U).
  const cv::Mat& validMask() const { return valid_mask_; }
  bool hasDistortion() const { return has_distortion_; }

  cv::Size size() const { return size_; }
  double fx() const { return fx_; }
  double fy() const { return fy_; }
  double cx() const { return cx_; }
  double cy() const { return cy_; }

  /// Pinhole-image pixel -> undistorted normalised coordinates (K^-1).
  Eigen::Vector2d pixelToNormalised(const Eigen::Vector2d& px) const {
    return {(px.x() - cx_) / fx_, (px.y() - cy_) / fy_};
  }
  Eigen::Vector2d normalisedToPixel(const Eigen::Vector2d& xy) const {
    return {fx_ * xy.x() + cx_, fy_ * xy.y() + cy_};
  }

 private:
  cv::Size size_;
  double fx_, fy_, cx_, cy_;
  bool has_distortion_;
  // A pinhole pixel whose 2x2 source neighbourhood is not wholly inside the raw image.
  struct BorderPixel {
    int index, source_x, source_y, fraction;
  };
  cv::Mat remapBilinear(const cv::Mat& raw) const;

  cv::Mat map_xy_, map_frac_;  // fixed-point remap tables (cv::convertMaps)
  // The same tables per pinhole pixel, row-major: the raw image offset of the top-left source
  // pixel (sy * width + sx; 0 for a border pixel) and the 5+5-bit sub-pixel fraction (y, x).
  std::vector<std::int32_t> source_offset_;
  std::vector<std::uint16_t> source_fraction_;
  std::vector<BorderPixel> border_pixels_;
  cv::Mat valid_mask_;
};

}  // namespace alvio
