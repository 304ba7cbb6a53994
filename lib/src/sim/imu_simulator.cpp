#include "alvio/sim/imu_simulator.h"

#include <cmath>

#include "alvio/common/error.h"
#include "alvio/sim/seeded_random.h"

namespace alvio::sim {

std::vector<int64_t> regularStamps(int64_t t_begin_ns, int64_t t_end_ns, double rate_hz) {
  if (!(rate_hz > 0)) throw Error("sample rate must be positive");
  std::vector<int64_t> stamps;
  const double period_ns = 1e9 / rate_hz;
  for (int64_t k = 0;; ++k) {
    const int64_t t = t_begin_ns + static_cast<int64_t>(std::llround(k * period_ns));
    if (t > t_end_ns) break;
    stamps.push_back(t);
  }
  return stamps;
}

GroundTruth sampleGroundTruth(const PoseSpline& spline, const std::vector<int64_t>& stamps_ns) {
  GroundTruth gt;
  gt.reserve(stamps_ns.size());
  for (const int64_t t_ns : stamps_ns) {
    const BodyState s = spline.state(nsToSec(t_ns));
    GroundTruthState g;
    g.t_ns = t_ns;
    g.p = s.p_w;
    g.q = s.q_w_b;
    g.v = s.v_w;
    gt.push_back(g);
  }
  return gt;
}

SimulatedImu simulateImu(const PoseSpline& spline, const std::vector<int64_t>& stamps_ns,
                         const ImuSimulationOptions& o) {
  const Eigen::Vector3d g_w(0, 0, -o.imu.gravity_magnitude);
  const double dt = 1.0 / o.imu.rate_hz;
  const double sqrt_rate = std::sqrt(o.imu.rate_hz);
  const double sigma_g = o.imu.gyroscope_noise_density * sqrt_rate;
  const double sigma_a = o.imu.accelerometer_noise_density * sqrt_rate;
  const double walk_g = o.imu.gyroscope_random_walk * std::sqrt(dt);
  const double walk_a = o.imu.accelerometer_random_walk * std::sqrt(dt);

  SeededRandom rng(mixSeed(o.seed, 0x1a2b3c4dULL));
  auto gaussian3 = [&rng](double sigma) -> Eigen::Vector3d {
    // Fixed evaluation order (x, y, z) so the stream is reproducible.
    const double x = rng.normal(), y = rng.normal(), z = rng.normal();
    return Eigen::Vector3d(x, y, z) * sigma;
  };

  SimulatedImu out;
  out.samples.reserve(stamps_ns.size());
  out.states.reserve(stamps_ns.size());
  Eigen::Vector3d bg = o.initial_gyro_bias, ba = o.initial_accel_bias;
  for (std::size_t k = 0; k < stamps_ns.size(); ++k) {
    const double t = nsToSec(stamps_ns[k]);
    if (!spline.contains(t))
      throw Error("IMU time " + std::to_string(t) + " s is outside the trajectory spline [" +
                  std::to_string(spline.startTime()) + ", " + std::to_string(spline.endTime()) +
                  "]");
    if (k > 0 && o.add_bias_random_walk) {
      // The walk is driven by the interval since the previous sample.
      const double dk = nsToSec(stamps_ns[k] - stamps_ns[k - 1]);
      const double scale = std::sqrt(dk / dt);
      bg += gaussian3(walk_g * scale);
      ba += gaussian3(walk_a * scale);
    }
    const BodyState s = spline.state(t);
    ImuSample m;
    m.t_ns = stamps_ns[k];
    m.gyr = s.omega_b + bg;
    m.acc = s.q_w_b.conjugate() * (s.a_w - g_w) + ba;
    if (o.add_noise) {
      m.gyr += gaussian3(sigma_g);
      m.acc += gaussian3(sigma_a);
    }
    out.samples.push_back(m);
    GroundTruthState g;
    g.t_ns = stamps_ns[k];
    g.p = s.p_w;
    g.q = s.q_w_b;
    g.v = s.v_w;
    g.bg = bg;
    g.ba = ba;
    out.states.push_back(g);
  }
  return out;
}

}  // namespace alvio::sim
