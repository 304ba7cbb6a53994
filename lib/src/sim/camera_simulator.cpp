#include "alvio/sim/camera_simulator.h"

#include <algorithm>

#include "alvio/sim/seeded_random.h"

namespace alvio::sim {

CameraSimulator::CameraSimulator(const Scene& scene, const SceneAppearance& appearance,
                                 const CameraModel& camera, const Eigen::Isometry3d& T_b_c,
                                 const CameraSimulationOptions& options)
    : T_b_c_(T_b_c), options_(options) {
  rays_ = std::make_unique<CameraRayTable>(camera, options.render.threads);
  renderer_ = std::make_unique<RadianceRenderer>(scene, appearance, *rays_);
  sensor_ = std::make_unique<ImageSensor>(*rays_, options.sensor);
}

void CameraSimulator::setExposureFromViews(const PoseSpline& trajectory,
                                           const std::vector<double>& times) {
  std::vector<cv::Mat1f> views;
  for (double t : times) views.push_back(radiance(cameraPose(trajectory, t)));
  sensor_->setExposureFrom(views);
}

cv::Mat1f CameraSimulator::radiance(const Eigen::Isometry3d& T_w_c) const {
  return renderer_->render(T_w_c, options_.render);
}

cv::Mat1b CameraSimulator::render(const PoseSpline& trajectory, double t, double t_rel) const {
  const int n = std::max(1, options_.motion_blur_samples);
  cv::Mat1f sum;
  if (n == 1 || options_.exposure_time_s <= 0) {
    sum = radiance(cameraPose(trajectory, t));
  } else {
    for (int k = 0; k < n; ++k) {
      const double tk = std::clamp(t + options_.exposure_time_s * ((k + 0.5) / n - 0.5),
                                   trajectory.startTime(), trajectory.endTime());
      const cv::Mat1f r = radiance(cameraPose(trajectory, tk));
      if (k == 0)
        sum = r;
      else
        sum += r;
    }
    sum *= 1.0 / n;
  }
  const uint64_t seed = mixSeed(options_.seed, static_cast<uint64_t>(std::llround(t * 1e9)));
  return sensor_->expose(sum, options_.illumination.factorAt(t_rel), seed);
}

}  // namespace alvio::sim
