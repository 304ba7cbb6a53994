#pragma once
// Synthetic grey images for the line tracker tests: dark bars (filled rotated rectangles) on a
// smooth random texture, rendered with anti-aliasing at sub-pixel positions. The whole scene is
// shifted between frames (texture included), so optical flow sees a consistent motion.

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "alvio/config/sensor_options.h"

namespace alvio::test {

/// A bar: centre, size (length along its axis, thickness) and axis angle [deg].
struct Bar {
  cv::Point2d centre;
  cv::Size2d size;
  double angle_deg = 0.0;
  int grey = 30;
};

/// A square of background texture covering a bar in one frame (splitting its edges).
struct Occluder {
  cv::Point2d centre;
  double half_size;
};

class SyntheticLineScene {
 public:
  /// Texture over a canvas `margin` px larger than the image on every side.
  explicit SyntheticLineScene(cv::Size image_size, unsigned seed = 7, int margin = 200)
      : size_(image_size), margin_(margin) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    const cv::Size canvas(size_.width + 2 * margin_, size_.height + 2 * margin_);
    cv::Mat coarse(canvas.height / 8, canvas.width / 8, CV_32FC1);
    for (int v = 0; v < coarse.rows; ++v)
      for (int c = 0; c < coarse.cols; ++c) coarse.at<float>(v, c) = u(rng);
    cv::Mat fine;
    cv::resize(coarse, fine, canvas, 0, 0, cv::INTER_CUBIC);
    fine.convertTo(texture_, CV_8UC1, 60.0, 110.0);  // grey 110..170: texture, no strong edges
  }

  /// The image seen with the scene shifted by `offset` pixels (bars and texture move).
  cv::Mat render(const std::vector<Bar>& bars, cv::Point2d offset,
                 const std::vector<Occluder>& occluders = {}) const {
    // Shift the texture with sub-pixel accuracy, then draw in image coordinates.
    const cv::Mat M =
        (cv::Mat_<double>(2, 3) << 1, 0, offset.x - margin_, 0, 1, offset.y - margin_);
    cv::Mat image;
    cv::warpAffine(texture_, image, M, size_, cv::INTER_LINEAR, cv::BORDER_REFLECT);
    for (const Bar& bar : bars) {
      cv::Point2f corners[4];
      cv::RotatedRect(cv::Point2f(bar.centre.x + offset.x, bar.centre.y + offset.y),
                      cv::Size2f(bar.size.width, bar.size.height),
                      static_cast<float>(bar.angle_deg))
          .points(corners);
      constexpr int kShift = 4;  // sub-pixel vertices
      std::vector<cv::Point> poly;
      for (const auto& c : corners)
        poly.emplace_back(cvRound(c.x * (1 << kShift)), cvRound(c.y * (1 << kShift)));
      cv::fillConvexPoly(image, poly, cv::Scalar(bar.grey), cv::LINE_AA, kShift);
    }
    for (const Occluder& o : occluders) {
      const cv::Rect r(cvRound(o.centre.x + offset.x - o.half_size),
                       cvRound(o.centre.y + offset.y - o.half_size), cvRound(2 * o.half_size),
                       cvRound(2 * o.half_size));
      cv::Mat background;
      cv::warpAffine(texture_, background, M, size_, cv::INTER_LINEAR, cv::BORDER_REFLECT);
      background(r & cv::Rect(cv::Point(), size_)).copyTo(image(r & cv::Rect(cv::Point(), size_)));
    }
    cv::GaussianBlur(image, image, cv::Size(3, 3), 0.7);
    return image;
  }

 private:
  cv::Size size_;
  int margin_;
  cv::Mat texture_;
};

/// EuRoC-sized pinhole camera without distortion.
inline CameraOptions undistortedCamera() {
  CameraOptions c;
  c.distortion_model = "none";
  c.distortion_coefficients.clear();
  return c;
}

}  // namespace alvio::test
