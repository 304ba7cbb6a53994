#include <gtest/gtest.h>

#include "alvio/config/config.h"
#include "alvio/estimator/initialization/visual_inertial_alignment.h"
#include "synthetic_scenario.h"
#include "test_support.h"

using namespace alvio;

// Frames with true rotations and camera positions scaled by 1/4 in a rotated
// reference frame: alignment must recover the gyro bias, scale 4 and gravity.
TEST(VisualInertialAlignment, RecoversScaleGravityAndGyroBias) {
  const Config c = Config::load(test::sourcePath("config/euroc.yaml"));
  test::ScenarioOptions so;
  so.duration_s = 3;
  so.imu_noise = false;
  const test::SyntheticScenario s(so, c.camera, c.imu);
  const Eigen::Matrix3d R_c0_w =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -1).normalized()).toRotationMatrix();
  const double true_scale = 4.0;
  std::vector<std::unique_ptr<ImuPreintegration>> pre;
  std::vector<AlignmentFrame> frames;
  const auto& imu = s.imu();
  std::size_t k = 0;
  double t_prev = -1;
  for (const auto& f : s.frames()) {
    const double t = f.t() - nsToSec(test::SyntheticScenario::kStartNs);
    if (t > 1.5) break;
    AlignmentFrame a;
    a.R_c0_b = R_c0_w * s.rotation(t);
    const Eigen::Vector3d p_w_c = s.position(t) + s.rotation(t) * c.camera.T_b_c.translation();
    a.p_c0_c = R_c0_w * p_w_c / true_scale;
    if (t_prev >= 0) {
      // Preintegrate the (biased) IMU from the previous frame, nearest samples.
      while (k + 1 < imu.size() &&
             imu[k + 1].t() - 1e-9 <= nsToSec(test::SyntheticScenario::kStartNs) + t_prev)
        ++k;
      auto p = std::make_unique<ImuPreintegration>(imu[k].acc, imu[k].gyr, Eigen::Vector3d::Zero(),
                                                   Eigen::Vector3d::Zero(), ImuNoise());
      while (k + 1 < imu.size() &&
             imu[k + 1].t() <= nsToSec(test::SyntheticScenario::kStartNs) + t + 1e-9) {
        p->push(imu[k + 1].t() - imu[k].t(), imu[k + 1].acc, imu[k + 1].gyr);
        ++k;
      }
      a.imu = p.get();
      pre.push_back(std::move(p));
    }
    frames.push_back(a);
    t_prev = t;
  }
  AlignmentResult r;
  ASSERT_TRUE(alignVisualInertial(frames, c.camera.T_b_c.translation(), 9.81, &r)) << r.failure;
  EXPECT_NEAR(r.scale, true_scale, 0.05 * true_scale);
  EXPECT_LT((r.gyro_bias - Eigen::Vector3d(0.002, -0.001, 0.003)).norm(), 1e-3);
  const Eigen::Vector3d g_up_c0 = R_c0_w * Eigen::Vector3d(0, 0, 9.81);
  EXPECT_LT(std::acos(r.gravity_c0.normalized().dot(g_up_c0.normalized())) * 180 / M_PI, 0.5);
}
