#include <gtest/gtest.h>

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
