#include <gtest/gtest.h>

#include <random>

#include "alvio/config/config.h"
#include "alvio/estimator/initialization/visual_inertial_alignment.h"
#include "synthetic_scenario.h"
#include "test_support.h"

using namespace alvio;

namespace {
const Eigen::Vector3d kTrueGyroBias(0.002, -0.001, 0.003);  // the scenario's
constexpr double kTrueScale = 4.0;

// The first 1.5 s: true rotations and camera positions scaled by 1 / kTrueScale in a rotated
// reference frame, each frame's (biased) IMU preintegrated from the previous frame, nearest
// samples, linearised at gyroscope bias `bg`.
struct AlignmentInput {
  std::vector<std::unique_ptr<ImuPreintegration>> pre;
  std::vector<AlignmentFrame> frames;
  Eigen::Matrix3d R_c0_w;
};

AlignmentInput alignmentInput(const test::SyntheticScenario& s, const Config& c,
                              const Eigen::Vector3d& bg) {
  AlignmentInput in;
  in.R_c0_w = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -1).normalized()).toRotationMatrix();
  const auto& imu = s.imu();
  const double t0 = nsToSec(test::SyntheticScenario::kStartNs);
  std::size_t k = 0;
  double t_prev = -1;
  for (const auto& f : s.frames()) {
    const double t = f.t() - t0;
    if (t > 1.5) break;
    AlignmentFrame a;
    a.R_c0_b = in.R_c0_w * s.rotation(t);
    const Eigen::Vector3d p_w_c = s.position(t) + s.rotation(t) * c.camera.T_b_c.translation();
    a.p_c0_c = in.R_c0_w * p_w_c / kTrueScale;
    if (t_prev >= 0) {
      while (k + 1 < imu.size() && imu[k + 1].t() - 1e-9 <= t0 + t_prev) ++k;
      auto p = std::make_unique<ImuPreintegration>(imu[k].acc, imu[k].gyr, Eigen::Vector3d::Zero(),
                                                   bg, ImuNoise());
      while (k + 1 < imu.size() && imu[k + 1].t() <= t0 + t + 1e-9) {
        p->push(imu[k + 1].t() - imu[k].t(), imu[k + 1].acc, imu[k + 1].gyr);
        ++k;
      }
      a.imu = p.get();
      in.pre.push_back(std::move(p));
    }
    in.frames.push_back(a);
    t_prev = t;
  }
  return in;
}

void expectRecovered(const Eigen::Vector3d& linearisation_bg) {
  const Config c = Config::load(test::sourcePath("config/euroc.yaml"));
  test::ScenarioOptions so;
  so.duration_s = 3;
  so.imu_noise = false;
  const test::SyntheticScenario s(so, c.camera, c.imu);
  AlignmentInput in = alignmentInput(s, c, linearisation_bg);
  AlignmentResult r;
  ASSERT_TRUE(alignVisualInertial(in.frames, c.camera.T_b_c.translation(), 9.81, &r)) << r.failure;
  EXPECT_NEAR(r.scale, kTrueScale, 0.05 * kTrueScale);
  EXPECT_LT((r.gyro_bias - kTrueGyroBias).norm(), 1e-3) << r.gyro_bias.transpose();
  const Eigen::Vector3d g_up_c0 = in.R_c0_w * Eigen::Vector3d(0, 0, 9.81);
  EXPECT_LT(std::acos(r.gravity_c0.normalized().dot(g_up_c0.normalized())) * 180 / M_PI, 0.5);
}
}  // namespace

// Alignment must recover the gyro bias, scale 4 and gravity.
TEST(VisualInertialAlignment, RecoversScaleGravityAndGyroBias) {
  expectRecovered(Eigen::Vector3d::Zero());
}

// After a reset the window's preintegrations are linearised at the bias kept from the run
// before: the solved bias is still the absolute one, not the correction to it.
TEST(VisualInertialAlignment, GyroBiasIsAbsoluteWhenLinearisedAtAnotherBias) {
  expectRecovered(Eigen::Vector3d(0.03, -0.02, 0.04));
}

namespace {
// 1.5 s at 20 Hz of a body that does not turn, moving along `p_w_b`, its IMU at 200 Hz without
// noise or bias, and visual positions scaled by 1 / kTrueScale with 2 mm of noise (metric).
template <typename Path>
AlignmentInput linearMotion(const Path& p_w_b, const Eigen::Vector3d& t_b_c) {
  AlignmentInput in;
  in.R_c0_w = Eigen::Matrix3d::Identity();
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.002);
  const auto specificForce = [&p_w_b](double t) {
    const double h = 1e-4;
    return Eigen::Vector3d((p_w_b(t + h) - 2 * p_w_b(t) + p_w_b(t - h)) / (h * h) +
                           Eigen::Vector3d(0, 0, 9.81));
  };
  for (int f = 0; f <= 30; ++f) {
    const double t = 0.05 * f;
    AlignmentFrame a;
    a.R_c0_b = Eigen::Matrix3d::Identity();
    const Eigen::Vector3d jitter(noise(rng), noise(rng), noise(rng));
    a.p_c0_c = (p_w_b(t) + t_b_c + jitter) / kTrueScale;
    if (f > 0) {
      const double t0 = t - 0.05;
      auto pre = std::make_unique<ImuPreintegration>(specificForce(t0), Eigen::Vector3d::Zero(),
                                                     Eigen::Vector3d::Zero(),
                                                     Eigen::Vector3d::Zero(), ImuNoise());
      for (int k = 1; k <= 10; ++k)
        pre->push(0.005, specificForce(t0 + 0.005 * k), Eigen::Vector3d::Zero());
      a.imu = pre.get();
      in.pre.push_back(std::move(pre));
    }
    in.frames.push_back(a);
  }
  return in;
}
}  // namespace

// Started mid-flight at nearly constant velocity, the scale is left to the noise: the alignment
// must say how uncertain it is, so that the estimator can wait for the motion to change.
TEST(VisualInertialAlignment, TellsHowWellTheMotionPinsTheScaleDown) {
  const Eigen::Vector3d t_b_c(0.02, -0.06, 0.01);
  const auto turning = [](double t) {
    return Eigen::Vector3d(0.8 * t + 0.3 * std::sin(3 * t), 0.4 * std::cos(3 * t), 0.1 * t);
  };
  const auto cruising = [](double t) {
    return Eigen::Vector3d(0.8 * t + 0.01 * std::sin(3 * t), 0.2 * t, 0.1 * t);
  };
  AlignmentInput accelerating = linearMotion(turning, t_b_c);
  AlignmentInput steady = linearMotion(cruising, t_b_c);
  AlignmentResult a, s;
  ASSERT_TRUE(alignVisualInertial(accelerating.frames, t_b_c, 9.81, &a)) << a.failure;
  EXPECT_NEAR(a.scale, kTrueScale, 0.05 * kTrueScale);
  // 2 mm of noise against the turn's tens of millimetres off constant velocity.
  EXPECT_GT(a.scale_motion_m, 0.02);
  EXPECT_LT(a.scale_motion_m, 0.5);
  // The steady window aligns, to a scale shrunk by the noise (0.05 here, not 4): only its
  // motion tells.
  ASSERT_TRUE(alignVisualInertial(steady.frames, t_b_c, 9.81, &s)) << s.failure;
  EXPECT_LT(s.scale_motion_m, 0.005) << "scale " << s.scale;
  EXPECT_LT(s.scale_motion_m, 0.1 * a.scale_motion_m);
}
