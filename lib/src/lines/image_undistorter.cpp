#include "alvio/lines/image_undistorter.h"

#include <opencv2/imgproc.hpp>

#include "alvio/camera/camera_model.h"

namespace alvio {

ImageUndistorter::ImageUndistorter(const CameraOptions& camera)
    : size_(camera.width, camera.height),
      fx_(camera.intrinsics[0]),
      fy_(camera.intrinsics[1]),
      cx_(camera.intrinsics[2]),
      cy_(camera.intrinsics[3]) {
  has_distortion_ = false;
  for (double c : camera.distortion_coefficients) has_distortion_ |= c != 0.0;
  valid_mask_ = cv::Mat(size_, CV_8UC1, cv::Scalar(255));
  if (!has_distortion_) return;

  // For every pinhole pixel: its normalised ray, distorted into the raw image.
  const auto model = CameraModel::create(camera);
  cv::Mat map_x(size_, CV_32FC1), map_y(size_, CV_32FC1);
  for (int v = 0; v < size_.height; ++v) {
    for (int u = 0; u < size_.width; ++u) {
      const Eigen::Vector2d raw = model->distort(pixelToNormalised(Eigen::Vector2d(u, v)));
      map_x.at<float>(v, u) = static_cast<float>(raw.x());
      map_y.at<float>(v, u) = static_cast<float>(raw.y());
    }
  }
  // Fixed-point tables make cv::remap several times faster than float ones.
  cv::convertMaps(map_x, map_y, map_xy_, map_frac_, CV_16SC2);
  const cv::Mat ones(size_, CV_8UC1, cv::Scalar(255));
  cv::remap(ones, valid_mask_, map_xy_, map_frac_, cv::INTER_NEAREST, cv::BORDER_CONSTANT,
            cv::Scalar(0));
}

cv::Mat ImageUndistorter::undistort(const cv::Mat& raw) const {
  if (!has_distortion_) return raw;
  cv::Mat out;
  cv::remap(raw, out, map_xy_, map_frac_, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  return out;
}

}  // namespace alvio
