#pragma once
// One camera frame at time t along a trajectory: camera pose = body pose (from
// the spline) composed with T_b_c, radiance by ray casting, optional motion blur
// (sub-exposures spread over the exposure time, averaged), then the sensor
// (illumination factor over time, blur, vignetting, noise).

#include <Eigen/Geometry>
#include <memory>
#include <opencv2/core.hpp>

#include "alvio/camera/camera_model.h"
#include "alvio/sim/illumination.h"
#include "alvio/sim/image_sensor.h"
#include "alvio/sim/pose_spline.h"
#include "alvio/sim/radiance_renderer.h"

namespace alvio::sim {

struct CameraSimulationOptions {
  RenderOptions render;
  SensorOptions sensor;
  IlluminationOptions illumination;
  double exposure_time_s = 0.0;  ///< motion blur over this time (centred on the stamp)
  int motion_blur_samples = 1;   ///< sub-exposures (1 = no motion blur)
  uint64_t seed = 1;
};

class CameraSimulator {
 public:
  /// References to `scene` and `appearance` are kept; they must outlive this object.
  CameraSimulator(const Scene& scene, const SceneAppearance& appearance, const CameraModel& camera,
                  const Eigen::Isometry3d& T_b_c, const CameraSimulationOptions& options);

  /// The 8-bit image at time t (seconds). `t_rel` is t relative to the sequence start,
  /// for the illumination profile. Deterministic in (seed, t).
  cv::Mat1b render(const PoseSpline& trajectory, double t, double t_rel) const;
  /// Auto exposure: fix the sensor's exposure from the views at these times (no-op
  /// when the sensor's target_mean_dn is 0). Call once, before rendering a sequence.
  void setExposureFromViews(const PoseSpline& trajectory, const std::vector<double>& times);
  double exposure() const { return sensor_->options().exposure_dn; }
  /// The noise-free radiance at one camera pose (no blur, no sensor).
  cv::Mat1f radiance(const Eigen::Isometry3d& T_w_c) const;

  Eigen::Isometry3d cameraPose(const PoseSpline& trajectory, double t) const {
    return trajectory.pose(t) * T_b_c_;
  }
  const CameraRayTable& rays() const { return *rays_; }
  const CameraSimulationOptions& options() const { return options_; }

 private:
  Eigen::Isometry3d T_b_c_;
  CameraSimulationOptions options_;
  std::unique_ptr<CameraRayTable> rays_;
  std::unique_ptr<RadianceRenderer> renderer_;
  std::unique_ptr<ImageSensor> sensor_;
};

}  // namespace alvio::sim
