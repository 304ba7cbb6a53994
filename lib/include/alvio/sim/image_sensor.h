#pragma once
// From radiance to an 8-bit image as a global-shutter CMOS camera (EuRoC's
// MT9V034) makes it: lens blur, vignetting, exposure and gain, photon (shot)
// noise whose variance grows with the signal, read noise, quantisation and
// clipping. Noise is seeded per image row, so the result does not depend on
// how many threads produced it.

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "alvio/sim/camera_ray_table.h"

namespace alvio::sim {

struct SensorOptions {
  double exposure_dn = 300.0;  ///< grey level (DN) of unit radiance at gain 1
  /// > 0: auto exposure, set once (then fixed, like a camera with exposure locked after
  /// start-up) so that the first frame's mean grey level is this many DN.
  double target_mean_dn = 115.0;
  double optical_blur_sigma_px = 0.6;  ///< Gaussian point-spread function (0 = sharp)
  double vignetting = 0.35;            ///< 0 none .. 1 the full cos^4 fall-off
  double read_noise_dn = 1.2;
  double shot_noise_dn = 0.12;  ///< variance added per DN of signal
  bool add_noise = true;
};

class ImageSensor {
 public:
  ImageSensor(const CameraRayTable& rays, const SensorOptions& options);

  const SensorOptions& options() const { return options_; }
  /// Fix exposure_dn so that these radiance images (after vignetting) have the
  /// target mean grey level on average.
  void setExposureFrom(const std::vector<cv::Mat1f>& radiance);
  /// `radiance` (linear) times `light_factor` (illumination over time) to 8 bits.
  cv::Mat1b expose(const cv::Mat1f& radiance, double light_factor, uint64_t seed) const;

 private:
  SensorOptions options_;
  cv::Mat1f vignette_;
};

}  // namespace alvio::sim
