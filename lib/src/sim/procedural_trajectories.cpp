#include "alvio/sim/procedural_trajectories.h"

#include <cmath>
#include <functional>

#include "alvio/common/angles.h"
#include "alvio/common/error.h"

namespace alvio::sim {
namespace {

double smoothstep(double x) {
  if (x <= 0) return 0;
  if (x >= 1) return 1;
  return x * x * x * (10 - 15 * x + 6 * x * x);  // C2 at both ends
}

/// Progress along the path (in "seconds at full speed"): 0 while still, then a
/// smooth ramp to unit rate. Integrated numerically; the result is smooth.
std::vector<double> progress(const ProceduralPathOptions& o, int n, double dt) {
  std::vector<double> s(n, 0.0);
  for (int k = 1; k < n; ++k) {
    const double t0 = (k - 1) * dt, t1 = k * dt;
    const double r0 = smoothstep((t0 - o.still_s) / o.ramp_s);
    const double r1 = smoothstep((t1 - o.still_s) / o.ramp_s);
    s[k] = s[k - 1] + 0.5 * (r0 + r1) * dt;
  }
  return s;
}

// Camera looking horizontally along `forward` (pitched by `pitch`, positive up), then tilted
// so that its up axis follows the specific force (a - g), as a multicopter does.
Eigen::Matrix3d cameraOrientation(const Eigen::Vector3d& forward_h, double pitch,
                                  const Eigen::Vector3d& accel_w) {
  const Eigen::Vector3d up(0, 0, 1);
  Eigen::Vector3d f = forward_h;
  f.z() = 0;
  f.normalize();
  f = (std::cos(pitch) * f + std::sin(pitch) * up).normalized();
  const Eigen::Vector3d right = f.cross(up).normalized();
  const Eigen::Vector3d down = f.cross(right);
  Eigen::Matrix3d R_w_c;
  R_w_c << right, down, f;
  const Eigen::Vector3d thrust = (accel_w + Eigen::Vector3d(0, 0, 9.81)).normalized();
  const Eigen::Quaterniond tilt = Eigen::Quaterniond::FromTwoVectors(up, thrust);
  return tilt.toRotationMatrix() * R_w_c;
}

using PathFn = std::function<void(double s, Eigen::Vector3d* p, Eigen::Vector3d* look)>;

Trajectory sampleCameraPath(const ProceduralPathOptions& o, const PathFn& path, double pitch) {
  const double dt = 1.0 / o.rate_hz;
  const int n = static_cast<int>(std::floor(o.duration_s * o.rate_hz)) + 1;
  const std::vector<double> s = progress(o, n + 2, dt);
  std::vector<Eigen::Vector3d, Eigen::aligned_allocator<Eigen::Vector3d>> pos(n + 2), look(n + 2);
  for (int k = 0; k < n + 2; ++k) path(s[k], &pos[k], &look[k]);
  const Eigen::Matrix3d R_b_c = o.T_b_c.linear();
  const Eigen::Vector3d t_b_c = o.T_b_c.translation();
  Trajectory out;
  out.reserve(n);
  for (int k = 0; k < n; ++k) {
    // Central difference for the tilt only (one step of lag at the start is harmless).
    const int km = std::max(k - 1, 0), kp = k + 1;
    const Eigen::Vector3d acc = (pos[kp] - 2 * pos[k] + pos[km]) / (dt * dt) * (k > 0 ? 1.0 : 0.0);
    const Eigen::Matrix3d R_w_c = cameraOrientation(look[k], pitch, acc);
    // The path describes the camera centre; the body sits at -R_b_c^T t_b_c from it.
    const Eigen::Matrix3d R_w_b = R_w_c * R_b_c.transpose();
    StampedPose pose;
    pose.t = o.start_time_s + k * dt;
    pose.q = Eigen::Quaterniond(R_w_b).normalized();
    pose.p = pos[k] - R_w_b * t_b_c;
    out.push_back(pose);
  }
  return out;
}

Trajectory figureEight(const ProceduralPathOptions& o) {
  const FigureEightOptions& f = o.figure_eight;
  const double w = 2 * M_PI / f.lap_period_s;
  auto path = [&](double s, Eigen::Vector3d* p, Eigen::Vector3d* look) {
    const double a = w * s;
    *p = f.center + Eigen::Vector3d(f.half_length_m * std::sin(a), f.half_width_m * std::sin(2 * a),
                                    f.height_amplitude_m * std::sin(0.5 * a));
    // The heading turns by half a revolution per lap, with a sway: over two laps the
    // camera sees every side of the scene, and rarely looks straight along its motion.
    const double yaw = 0.5 * a + 0.4 * std::sin(a);
    *look = Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0);
  };
  return sampleCameraPath(o, path, -0.12);
}

Trajectory corridorWalk(const ProceduralPathOptions& o) {
  const CorridorWalkOptions& c = o.corridor;
  const double lap = 2 * c.length_m / c.speed_mps;  // there and back
  const double sway = c.look_around_deg * kDegToRad;
  auto path = [&](double s, Eigen::Vector3d* p, Eigen::Vector3d* look) {
    // x follows a smooth back-and-forth (cosine) so the turn-around is not a cusp.
    const double phase = 2 * M_PI * s / lap;
    const double x = 0.5 * c.length_m * (1 - std::cos(phase));
    const double step = 2 * M_PI * 1.8 * s;  // walking gait, 1.8 Hz
    *p = c.start + Eigen::Vector3d(x, 0.08 * std::sin(0.5 * step) + 0.25 * std::sin(0.7 * phase),
                                   0.02 * std::sin(step) * std::min(1.0, s));
    // Facing the walking direction, turning round at the ends (a smooth staircase in
    // yaw, steepest where the walker stops), looking around while walking. The fading
    // offset makes the start look diagonally down the corridor rather than at a wall.
    const double x_turn = phase / M_PI + 0.2 * std::exp(-s / 2.0);
    const double yaw = M_PI * (x_turn + std::sin(2 * M_PI * x_turn) / (2 * M_PI)) - 0.5 * M_PI +
                       sway * std::sin(0.37 * step / 1.8);
    *look = Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0);
  };
  return sampleCameraPath(o, path, -0.05);
}

}  // namespace

std::vector<std::string> proceduralTrajectoryNames() {
  return {"figure8", "corridor"};
}

bool isProceduralTrajectoryName(const std::string& name) {
  for (const auto& n : proceduralTrajectoryNames())
    if (n == name) return true;
  return false;
}

Trajectory makeProceduralTrajectory(const std::string& name, const ProceduralPathOptions& o) {
  if (!(o.duration_s > 0) || o.still_s < 0 || !(o.ramp_s > 0) || !(o.rate_hz > 0))
    throw Error("procedural trajectory: duration, ramp and rate must be positive, still >= 0");
  if (name == "figure8") return figureEight(o);
  if (name == "corridor") return corridorWalk(o);
  throw Error("unknown built-in trajectory '" + name + "' (known: figure8, corridor)");
}

}  // namespace alvio::sim
