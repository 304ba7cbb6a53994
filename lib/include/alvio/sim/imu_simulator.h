#pragma once
// Synthetic IMU measurements from a PoseSpline:
//   a_meas = R_w_b^T (a_w - g_w) + b_a + n_a,   w_meas = omega_b + b_g + n_g,
// with g_w = (0, 0, -g), white noise of sigma = density * sqrt(rate) and biases
// that random-walk with step sigma = random_walk * sqrt(dt).

#include <cstdint>
#include <vector>

#include "alvio/common/types.h"
#include "alvio/config/sensor_options.h"
#include "alvio/sim/pose_spline.h"

namespace alvio::sim {

struct ImuSimulationOptions {
  ImuOptions imu;  ///< noise densities, random walks, rate, gravity
  bool add_noise = true;
  bool add_bias_random_walk = true;
  /// Biases at the first sample. Defaults: the order of magnitude EuRoC's ADIS16448
  /// shows (MH_05 ground truth at its start).
  Eigen::Vector3d initial_gyro_bias{-0.0018, 0.0209, 0.0769};
  Eigen::Vector3d initial_accel_bias{-0.0205, 0.1248, 0.0618};
  uint64_t seed = 1;
};

struct SimulatedImu {
  std::vector<ImuSample> samples;
  /// The true state at each sample time (pose, velocity, biases), EuRoC-style.
  GroundTruth states;
};

/// Measurements at the given times (each inside the spline's domain).
SimulatedImu simulateImu(const PoseSpline& spline, const std::vector<int64_t>& stamps_ns,
                         const ImuSimulationOptions& options);

/// Stamps at `rate_hz` covering [t_begin_ns, t_end_ns], on the grid t_begin + k / rate.
std::vector<int64_t> regularStamps(int64_t t_begin_ns, int64_t t_end_ns, double rate_hz);

/// The true state (no biases) of the spline at the given times.
GroundTruth sampleGroundTruth(const PoseSpline& spline, const std::vector<int64_t>& stamps_ns);

}  // namespace alvio::sim
