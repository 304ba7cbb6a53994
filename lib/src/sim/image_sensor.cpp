#include "alvio/sim/image_sensor.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

#include "alvio/sim/seeded_random.h"

namespace alvio::sim {
namespace {

// Standard normal samples by inverting the CDF through a table (4096 quantiles,
// linear interpolation): several times faster than Box-Muller per pixel, and
// exactly reproducible. The tails are cut at about 3.9 sigma, invisible in 8 bits.
class FastNormal {
 public:
  FastNormal() {
    for (int i = 0; i <= kSize; ++i) {
      const double p = (i + 0.5) / (kSize + 1.0);
      table_[i] = static_cast<float>(inverseNormalCdf(p));
    }
  }
  float operator()(SeededRandom& rng) const {
    const uint64_t r = rng.next();
    const float pos = static_cast<float>(r >> 40) * (kSize / 16777216.0f);  // 24 bits
    const int i = static_cast<int>(pos);
    return table_[i] + (pos - i) * (table_[i + 1] - table_[i]);
  }

 private:
  static constexpr int kSize = 4096;
  // Acklam's rational approximation (relative error < 1.2e-9).
  static double inverseNormalCdf(double p) {
    static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,
                               -2.759285104469687e+02, 1.383577518672690e+02,
                               -3.066479806614716e+01, 2.506628277459239e+00};
    static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02,
                               -1.556989798598866e+02, 6.680131188771972e+01,
                               -1.328068155288572e+01};
    static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01,
                               -2.400758277161838e+00, -2.549732539343734e+00,
                               4.374664141464968e+00,  2.938163982698783e+00};
    static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                               3.754408661907416e+00};
    const double lo = 0.02425;
    if (p < lo) {
      const double q = std::sqrt(-2 * std::log(p));
      return (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
             ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
    }
    if (p > 1 - lo) return -inverseNormalCdf(1 - p);
    const double q = p - 0.5, r = q * q;
    return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
           (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
  }
  float table_[kSize + 1];
};

}  // namespace

ImageSensor::ImageSensor(const CameraRayTable& rays, const SensorOptions& options)
    : options_(options), vignette_(rays.height(), rays.width()) {
  for (int v = 0; v < rays.height(); ++v)
    for (int u = 0; u < rays.width(); ++u) {
      const float c = rays.centerRay(u, v).z();  // cos of the angle to the optical axis
      const float c4 = c * c * c * c;
      vignette_(v, u) = static_cast<float>(1.0 - options.vignetting * (1.0 - c4));
    }
}

void ImageSensor::setExposureFrom(const std::vector<cv::Mat1f>& radiance) {
  if (options_.target_mean_dn <= 0 || radiance.empty()) return;
  double mean = 0;
  for (const cv::Mat1f& r : radiance) mean += cv::mean(r.mul(vignette_))[0] / radiance.size();
  if (mean > 1e-6) options_.exposure_dn = options_.target_mean_dn / mean;
}

cv::Mat1b ImageSensor::expose(const cv::Mat1f& radiance, double light_factor, uint64_t seed) const {
  cv::Mat1f signal;
  if (options_.optical_blur_sigma_px > 0)
    cv::GaussianBlur(radiance, signal, cv::Size(0, 0), options_.optical_blur_sigma_px, 0,
                     cv::BORDER_REPLICATE);
  else
    signal = radiance.clone();
  const float scale = static_cast<float>(options_.exposure_dn * light_factor);
  cv::Mat1b out(signal.rows, signal.cols);
  const float read2 = static_cast<float>(options_.read_noise_dn * options_.read_noise_dn);
  const float shot = static_cast<float>(options_.shot_noise_dn);
  static const FastNormal normal;
  for (int v = 0; v < signal.rows; ++v) {
    SeededRandom rng(mixSeed(seed, 0x5e75, static_cast<uint64_t>(v)));
    const float* s = signal.ptr<float>(v);
    const float* g = vignette_.ptr<float>(v);
    uint8_t* o = out.ptr<uint8_t>(v);
    for (int u = 0; u < signal.cols; ++u) {
      float dn = s[u] * g[u] * scale;
      if (options_.add_noise) dn += std::sqrt(read2 + shot * std::max(dn, 0.0f)) * normal(rng);
      o[u] = static_cast<uint8_t>(std::clamp(std::lround(dn), 0L, 255L));
    }
  }
  return out;
}

}  // namespace alvio::sim
