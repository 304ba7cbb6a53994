#include "synthetic_scenario.h"

#include <algorithm>
#include <set>

#include "alvio/camera/camera_model.h"
#include "alvio/common/rotation.h"

namespace alvio::test {

SyntheticScenario::SyntheticScenario(const ScenarioOptions& options, const CameraOptions& camera,
                                     const ImuOptions& imu)
    : options_(options), rng_(options.seed) {
  // Landmarks on the walls, floor and ceiling of a 12 x 12 x 5 m room around the path.
  std::uniform_real_distribution<double> u(-6, 6), h(-1, 4);
  for (int i = 0; i < 4000; ++i) {
    const int face = i % 6;
    Eigen::Vector3d p;
    if (face == 0)
      p = {6, u(rng_), h(rng_)};
    else if (face == 1)
      p = {-6, u(rng_), h(rng_)};
    else if (face == 2)
      p = {u(rng_), 6, h(rng_)};
    else if (face == 3)
      p = {u(rng_), -6, h(rng_)};
    else if (face == 4)
      p = {u(rng_), u(rng_), -1};
    else
      p = {u(rng_), u(rng_), 4};
    landmarks_.push_back(p);
  }
  // Horizontal and vertical segments (door frames, shelves, pipes) on the walls.
  std::uniform_real_distribution<double> len(0.6, 2.0);
  for (int i = 0; i < 300; ++i) {
    const int face = i % 4;
    const double a = u(rng_) * 0.8, z = h(rng_) * 0.8 + 0.3, l = len(rng_);
    const bool vertical = (i / 4) % 2 == 0;
    Eigen::Vector3d p0, dir;
    if (face == 0)
      p0 = {6, a, z}, dir = vertical ? Eigen::Vector3d(0, 0, 1) : Eigen::Vector3d(0, 1, 0);
    else if (face == 1)
      p0 = {-6, a, z}, dir = vertical ? Eigen::Vector3d(0, 0, 1) : Eigen::Vector3d(0, 1, 0);
    else if (face == 2)
      p0 = {a, 6, z}, dir = vertical ? Eigen::Vector3d(0, 0, 1) : Eigen::Vector3d(1, 0, 0);
    else
      p0 = {a, -6, z}, dir = vertical ? Eigen::Vector3d(0, 0, 1) : Eigen::Vector3d(1, 0, 0);
    segments_.emplace_back(p0 - 0.5 * l * dir, p0 + 0.5 * l * dir);
  }
  makeImu(imu);
  makeFrames(camera);
}

Eigen::Vector3d SyntheticScenario::position(double t) const {
  // A figure-eight-like path of a few metres with vertical motion; ramps in over 1 s.
  const double r = t < 1.0 ? t * t * (3 - 2 * t) : 1.0;
  return r *
         Eigen::Vector3d(2.0 * std::sin(0.8 * t), 1.5 * std::sin(1.4 * t), 0.4 * std::sin(1.1 * t));
}

Eigen::Matrix3d SyntheticScenario::rotation(double t) const {
  const double yaw = 0.6 * std::sin(0.3 * t) + 0.2 * t;
  const double pitch = 0.1 * std::sin(0.9 * t);
  const double roll = 0.1 * std::cos(0.8 * t);
  // Mounted as on the EuRoC MAV: body x up, body z (the camera's axis) forward.
  Eigen::Matrix3d R0;
  R0 << 0, 0, 1, 0, -1, 0, 1, 0, 0;
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
             .toRotationMatrix() *
         R0;
}

Eigen::Vector3d SyntheticScenario::velocity(double t) const {
  const double h = 1e-5;
  return (position(t + h) - position(t - h)) / (2 * h);
}

void SyntheticScenario::makeImu(const ImuOptions& imu) {
  const double dt = 1.0 / options_.imu_rate_hz;
  const double h = 1e-4;
  std::normal_distribution<double> n(0, 1);
  const double sa = imu.accelerometer_noise_density / std::sqrt(dt);
  const double sg = imu.gyroscope_noise_density / std::sqrt(dt);
  Eigen::Vector3d ba(0.05, -0.03, 0.02), bg(0.002, -0.001, 0.003);
  const Eigen::Vector3d g(0, 0, -imu.gravity_magnitude);
  const int n_samples = static_cast<int>(options_.duration_s * options_.imu_rate_hz) + 1;
  for (int k = 0; k < n_samples; ++k) {
    const double t = k * dt;
    const Eigen::Vector3d a_w = (position(t + h) - 2 * position(t) + position(t - h)) / (h * h);
    const Eigen::Matrix3d R = rotation(t);
    const Eigen::Vector3d w =
        logQuaternion(Eigen::Quaterniond(R.transpose() * rotation(t + h))) / h;
    ImuSample s;
    s.t_ns = kStartNs + static_cast<int64_t>(std::llround(t * 1e9));
    s.acc = R.transpose() * (a_w - g) + ba;
    s.gyr = w + bg;
    if (options_.imu_noise) {
      s.acc += Eigen::Vector3d(n(rng_), n(rng_), n(rng_)) * sa;
      s.gyr += Eigen::Vector3d(n(rng_), n(rng_), n(rng_)) * sg;
      ba += Eigen::Vector3d(n(rng_), n(rng_), n(rng_)) * imu.accelerometer_random_walk *
            std::sqrt(dt);
      bg += Eigen::Vector3d(n(rng_), n(rng_), n(rng_)) * imu.gyroscope_random_walk * std::sqrt(dt);
    }
    imu_.push_back(s);
  }
}

void SyntheticScenario::makeFrames(const CameraOptions& camera) {
  const auto cam = CameraModel::create(camera);
  std::normal_distribution<double> n(0, options_.pixel_noise);
  // Track IDs: a landmark keeps its ID while tracked; once lost it gets a new one when seen
  // again, as a real tracker would.
  std::set<int> tracked;
  std::vector<int> track_id(landmarks_.size());
  for (std::size_t i = 0; i < track_id.size(); ++i) track_id[i] = static_cast<int>(i);
  int next_id = static_cast<int>(landmarks_.size());
  const int n_frames = static_cast<int>(options_.duration_s * options_.camera_rate_hz) - 1;
  for (int k = 0; k < n_frames; ++k) {
    const double t = 0.5 / options_.camera_rate_hz + k / options_.camera_rate_hz;
    const Eigen::Isometry3d T_w_c =
        Eigen::Translation3d(position(t)) * Eigen::Quaterniond(rotation(t)) * camera.T_b_c;
    const Eigen::Isometry3d T_c_w = T_w_c.inverse();
    std::vector<std::pair<int, Eigen::Vector2d>> visible;
    for (int i = 0; i < static_cast<int>(landmarks_.size()); ++i) {
      const Eigen::Vector3d p_c = T_c_w * landmarks_[i];
      Eigen::Vector2d px;
      if (p_c.z() < 0.3 || !cam->project(p_c, &px) || !cam->inImage(px, 5)) continue;
      visible.emplace_back(i, px);
    }
    // Keep tracked points first (as a tracker does), then new ones, up to max_points.
    std::stable_partition(visible.begin(), visible.end(),
                          [&](const auto& v) { return tracked.count(v.first) > 0; });
    if (static_cast<int>(visible.size()) > options_.max_points) visible.resize(options_.max_points);
    FeatureFrame frame;
    frame.t_ns = kStartNs + static_cast<int64_t>(std::llround(t * 1e9));
    std::set<int> now;
    for (const auto& [id, px] : visible) {
      if (!tracked.count(id) && k > 0) track_id[id] = next_id++;
      PointObservation o;
      o.id = track_id[id];
      o.px = px + Eigen::Vector2d(n(rng_), n(rng_));
      o.xy = cam->undistort(o.px);
      frame.points.push_back(o);
      now.insert(id);
    }
    tracked = now;
    addLines(T_c_w, camera, &frame);
    frames_.push_back(frame);
  }
}

Trajectory SyntheticScenario::groundTruth() const {
  Trajectory gt;
  for (double t = 0; t <= options_.duration_s; t += 0.005) {
    StampedPose p;
    p.t = nsToSec(kStartNs) + t;
    p.p = position(t);
    p.q = Eigen::Quaterniond(rotation(t));
    gt.push_back(p);
  }
  return gt;
}

}  // namespace alvio::test

namespace alvio::test {

void SyntheticScenario::addLines(const Eigen::Isometry3d& T_c_w, const CameraOptions& camera,
                                 FeatureFrame* frame) {
  if (options_.max_lines <= 0) return;
  const double fx = camera.intrinsics[0], fy = camera.intrinsics[1];
  const double cx = camera.intrinsics[2], cy = camera.intrinsics[3];
  std::normal_distribution<double> n(0, options_.line_noise);
  std::uniform_real_distribution<double> shrink(0.0, 0.05);
  std::vector<int> visible;
  for (int i = 0; i < static_cast<int>(segments_.size()); ++i) {
    const Eigen::Vector3d a = T_c_w * segments_[i].first, b = T_c_w * segments_[i].second;
    if (a.z() < 0.5 || b.z() < 0.5) continue;
    const Eigen::Vector2d pa(fx * a.x() / a.z() + cx, fy * a.y() / a.z() + cy);
    const Eigen::Vector2d pb(fx * b.x() / b.z() + cx, fy * b.y() / b.z() + cy);
    auto inside = [&](const Eigen::Vector2d& p) {
      return p.x() > 5 && p.y() > 5 && p.x() < camera.width - 5 && p.y() < camera.height - 5;
    };
    if (inside(pa) && inside(pb) && (pa - pb).norm() > 40) visible.push_back(i);
  }
  std::stable_partition(visible.begin(), visible.end(),
                        [&](int i) { return tracked_lines_.count(i) > 0; });
  if (static_cast<int>(visible.size()) > options_.max_lines) visible.resize(options_.max_lines);
  std::set<int> now;
  for (int i : visible) {
    if (!tracked_lines_.count(i)) line_track_id_[i] = next_line_id_++;
    const Eigen::Vector3d a = T_c_w * segments_[i].first, b = T_c_w * segments_[i].second;
    Eigen::Vector2d pa(fx * a.x() / a.z() + cx, fy * a.y() / a.z() + cy);
    Eigen::Vector2d pb(fx * b.x() / b.z() + cx, fy * b.y() / b.z() + cy);
    // Detected endpoints wander along the line and jitter across it.
    const Eigen::Vector2d dir = (pb - pa).normalized(), normal(-dir.y(), dir.x());
    const Eigen::Vector2d sa = pa + shrink(rng_) * (pb - pa) + n(rng_) * normal;
    const Eigen::Vector2d sb = pb - shrink(rng_) * (pb - pa) + n(rng_) * normal;
    LineObservation o;
    o.id = line_track_id_[i];
    o.start_px = sa;
    o.end_px = sb;
    o.start_norm = Eigen::Vector2d((sa.x() - cx) / fx, (sa.y() - cy) / fy);
    o.end_norm = Eigen::Vector2d((sb.x() - cx) / fx, (sb.y() - cy) / fy);
    frame->lines.push_back(o);
    now.insert(i);
  }
  tracked_lines_ = now;
}

}  // namespace alvio::test
