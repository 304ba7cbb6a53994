// Synthetic IMU: integrating the noise-free measurements from the true initial
// state must reproduce the trajectory (1 cm, 0.1 deg after 10 s).
#include <gtest/gtest.h>

#include "alvio/config/config.h"
#include "alvio/io/trajectory_io.h"
#include "alvio/sim/imu_simulator.h"
#include "alvio/sim/pose_spline_fit.h"
#include "alvio/sim/procedural_trajectories.h"
#include "alvio/sim/so3.h"
#include "test_support.h"

using namespace alvio;
using namespace alvio::sim;

namespace {

struct NavState {
  Eigen::Quaterniond q;
  Eigen::Vector3d v, p;
};

// Time derivative of (q, v, p) for body rate w and specific force f (both in the body frame).
struct Derivative {
  Eigen::Vector4d dq;
  Eigen::Vector3d dv, dp;
};
Derivative derivative(const NavState& s, const Eigen::Vector3d& w, const Eigen::Vector3d& f,
                      const Eigen::Vector3d& g) {
  Derivative d;
  const Eigen::Quaterniond wq(0, w.x(), w.y(), w.z());
  d.dq = 0.5 * (s.q * wq).coeffs();
  d.dv = s.q * f + g;
  d.dp = s.v;
  return d;
}
NavState step(const NavState& s, const Derivative& d, double h) {
  NavState o;
  o.q.coeffs() = s.q.coeffs() + h * d.dq;
  o.v = s.v + h * d.dv;
  o.p = s.p + h * d.dp;
  return o;
}

// Classic RK4 over pairs of samples: k, k+1 (midpoint), k+2, step 2 dt.
NavState integrate(const NavState& start, const std::vector<ImuSample>& imu, int steps,
                   double gravity) {
  const Eigen::Vector3d g(0, 0, -gravity);
  NavState s = start;
  for (int k = 0; k + 2 <= steps; k += 2) {
    const double h = imu[k + 2].t() - imu[k].t();
    const Derivative k1 = derivative(s, imu[k].gyr, imu[k].acc, g);
    const Derivative k2 = derivative(step(s, k1, h / 2), imu[k + 1].gyr, imu[k + 1].acc, g);
    const Derivative k3 = derivative(step(s, k2, h / 2), imu[k + 1].gyr, imu[k + 1].acc, g);
    const Derivative k4 = derivative(step(s, k3, h), imu[k + 2].gyr, imu[k + 2].acc, g);
    s.q.coeffs() += h / 6 * (k1.dq + 2 * k2.dq + 2 * k3.dq + k4.dq);
    s.q.normalize();
    s.v += h / 6 * (k1.dv + 2 * k2.dv + 2 * k3.dv + k4.dv);
    s.p += h / 6 * (k1.dp + 2 * k2.dp + 2 * k3.dp + k4.dp);
  }
  return s;
}

void expectDeadReckoningMatches(const PoseSpline& spline, double t_begin) {
  ImuSimulationOptions o;
  o.add_noise = false;
  o.add_bias_random_walk = false;
  o.initial_accel_bias.setZero();
  o.initial_gyro_bias.setZero();
  const int64_t t0 = secToNs(t_begin);
  const SimulatedImu imu = simulateImu(spline, regularStamps(t0, t0 + secToNs(10.0), 200.0), o);
  ASSERT_EQ(imu.samples.size(), 2001u);
  const BodyState s0 = spline.state(imu.samples.front().t());
  const NavState end = integrate({s0.q_w_b, s0.v_w, s0.p_w}, imu.samples, 2000, 9.81);
  const BodyState s1 = spline.state(imu.samples.back().t());
  const double dp = (end.p - s1.p_w).norm();
  const double dr = so3Log(Eigen::Quaterniond(end.q.conjugate() * s1.q_w_b)).norm() * 180 / M_PI;
  EXPECT_LT(dp, 0.01) << "position error after 10 s";
  EXPECT_LT(dr, 0.1) << "rotation error after 10 s [deg]";
  // It must have moved, or the test would prove nothing.
  EXPECT_GT((s1.p_w - s0.p_w).norm() + (s1.v_w - s0.v_w).norm(), 0.5);
  std::cout << "dead reckoning over 10 s: " << dp * 1000 << " mm, " << dr << " deg\n";
}

}  // namespace

TEST(ImuSimulator, NoiseFreeImuIntegratesBackToTheFigureEight) {
  ProceduralPathOptions o;
  o.duration_s = 20;
  o.still_s = 1;
  o.ramp_s = 2;
  const Trajectory path = makeProceduralTrajectory("figure8", o);
  const PoseSpline spline = fitPoseSpline(path);
  expectDeadReckoningMatches(spline, 5.0);
}

TEST(ImuSimulator, NoiseFreeImuIntegratesBackToEurocMh05) {
  ALVIO_REQUIRE_SHARED_DATA(data);
  const Trajectory all =
      readTrajectory(data + "/euroc_groundtruth/xygxgn_VINS-Fusion/output/MH_05_difficult.txt");
  Trajectory part;  // 12 s of fast flight, with the real trajectory's accelerations
  for (const auto& p : all)
    if (p.t >= all.front().t + 30 && p.t <= all.front().t + 42) part.push_back(p);
  const PoseSpline spline = fitPoseSpline(part);
  expectDeadReckoningMatches(spline, part.front().t + 1.0);
}

TEST(ImuSimulator, StationaryImuMeasuresGravityAndTheBiases) {
  Vector3dList p(6, Eigen::Vector3d(1, 2, 3));
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 0.5).normalized()));
  const PoseSpline still(0.0, 0.1, p, QuaternionList(6, q));
  ImuSimulationOptions o;
  o.add_noise = false;
  o.add_bias_random_walk = false;
  const SimulatedImu imu = simulateImu(still, regularStamps(0, secToNs(0.3), 200.0), o);
  for (const auto& m : imu.samples) {
    EXPECT_LT((m.acc - (q.conjugate() * Eigen::Vector3d(0, 0, 9.81) + o.initial_accel_bias)).norm(),
              1e-12);
    EXPECT_LT((m.gyr - o.initial_gyro_bias).norm(), 1e-12);
  }
}

TEST(ImuSimulator, NoiseHasTheConfiguredDiscreteSigmaAndIsSeeded) {
  Vector3dList p(6, Eigen::Vector3d::Zero());
  const PoseSpline still(0.0, 100.0, p, QuaternionList(6, Eigen::Quaterniond::Identity()));
  ImuSimulationOptions o;
  o.add_bias_random_walk = false;
  o.seed = 42;
  const auto stamps = regularStamps(0, secToNs(100.0), 200.0);
  const SimulatedImu a = simulateImu(still, stamps, o);
  double sg = 0, sa = 0;
  for (const auto& m : a.samples) {
    sg += (m.gyr - o.initial_gyro_bias).squaredNorm();
    sa += (m.acc - Eigen::Vector3d(0, 0, 9.81) - o.initial_accel_bias).squaredNorm();
  }
  const double n = 3.0 * a.samples.size();
  EXPECT_NEAR(std::sqrt(sg / n), o.imu.gyroscope_noise_density * std::sqrt(200.0), 2e-5);
  EXPECT_NEAR(std::sqrt(sa / n), o.imu.accelerometer_noise_density * std::sqrt(200.0), 2e-4);
  const SimulatedImu b = simulateImu(still, stamps, o);
  o.seed = 43;
  const SimulatedImu c = simulateImu(still, stamps, o);
  EXPECT_EQ(a.samples[123].acc, b.samples[123].acc);
  EXPECT_NE(a.samples[123].acc, c.samples[123].acc);
}

TEST(ImuSimulator, BiasRandomWalkGrowsWithTheConfiguredRate) {
  Vector3dList p(6, Eigen::Vector3d::Zero());
  const PoseSpline still(0.0, 100.0, p, QuaternionList(6, Eigen::Quaterniond::Identity()));
  ImuSimulationOptions o;
  o.add_noise = false;
  // Many independent 100 s walks: the spread of the end value is random_walk * sqrt(100 s).
  double sum_g = 0, sum_a = 0;
  const int runs = 40;
  for (int r = 0; r < runs; ++r) {
    o.seed = 1000 + r;
    const SimulatedImu imu = simulateImu(still, regularStamps(0, secToNs(100.0), 200.0), o);
    sum_g += (imu.states.back().bg - o.initial_gyro_bias).squaredNorm();
    sum_a += (imu.states.back().ba - o.initial_accel_bias).squaredNorm();
  }
  const double sigma_g = std::sqrt(sum_g / (3 * runs)), sigma_a = std::sqrt(sum_a / (3 * runs));
  EXPECT_NEAR(sigma_g / (o.imu.gyroscope_random_walk * 10.0), 1.0, 0.25);
  EXPECT_NEAR(sigma_a / (o.imu.accelerometer_random_walk * 10.0), 1.0, 0.25);
}
