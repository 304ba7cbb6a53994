#include <gtest/gtest.h>

#include <cmath>

#include "alvio/config/config.h"
#include "alvio/config/yaml_reader.h"
#include "alvio/pipeline/odometry_covariance.h"
#include "test_support.h"

using namespace alvio;

namespace {
constexpr double kDeg = M_PI / 180.0;

OdometryCovarianceOptions someOptions() {
  OdometryCovarianceOptions o;
  o.position_sigma_m = 0.03;
  o.position_drift = 0.002;
  o.tilt_sigma_deg = 0.2;
  o.yaw_sigma_deg = 1.0;
  o.yaw_drift_deg_per_m = 0.01;
  o.velocity_sigma_mps = Eigen::Vector3d::Constant(0.01);
  o.angular_rate_sigma_rps = Eigen::Vector3d(0.0025, 0.005, 0.004);
  return o;
}

void expectDiagonal(const Covariance6& c, const std::array<double, 6>& variances) {
  for (int r = 0; r < 6; ++r)
    for (int col = 0; col < 6; ++col)
      EXPECT_NEAR(c[r * 6 + col], r == col ? variances[r] : 0.0, 1e-15) << r << "," << col;
}
}  // namespace

TEST(OdometryCovariance, PositionAndYawGrowWithThePathTiltAndTwistDoNot) {
  const OdometryCovarianceOptions o = someOptions();
  OdometryCovariance model(o);
  const double tilt = std::pow(0.2 * kDeg, 2);
  // Before any motion: the sigmas at the start.
  model.addPose(0.0, Eigen::Vector3d(1, 2, 3));
  expectDiagonal(model.pose(), {9e-4, 9e-4, 9e-4, tilt, tilt, std::pow(kDeg, 2)});
  // 100 m along a square's sides and back: the path counts, not the distance from the start.
  double t = 0.0;
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(26, 2, 3), Eigen::Vector3d(26, 27, 3),
                                   Eigen::Vector3d(1, 27, 3), Eigen::Vector3d(1, 2, 3)})
    model.addPose(t += 0.05, p);
  EXPECT_NEAR(model.pathLength(), 100.0, 1e-12);
  const double position = 0.03 * 0.03 + 0.2 * 0.2;  // 0.002 m/m over 100 m
  const double yaw = (1.0 + 1.0) * kDeg * kDeg;     // 0.01 deg/m over 100 m
  expectDiagonal(model.pose(), {position, position, position, tilt, tilt, yaw});
  expectDiagonal(model.twist(), {1e-4, 1e-4, 1e-4, 6.25e-6, 2.5e-5, 1.6e-5});
  // A new run starts its path again; a non-finite position is not a step.
  model.startNewRun();
  model.addPose(0.0, Eigen::Vector3d(50, 0, 0));
  model.addPose(0.05, Eigen::Vector3d(NAN, 0, 0));
  model.addPose(0.1, Eigen::Vector3d(53, 4, 0));
  EXPECT_NEAR(model.pathLength(), 5.0, 1e-12);
}

TEST(OdometryCovariance, EachOutageWidensPositionAndYawByItsLengthUntilANewRun) {
  OdometryCovarianceOptions o = someOptions();
  o.outage_min_s = 0.3;
  o.outage_position_sigma_mps = 0.01;
  o.outage_position_sigma_mps2 = 0.004;
  o.outage_yaw_sigma_deg_per_s = 0.02;
  OdometryCovariance model(o);
  // 50 m with pauses of 0.25 s (under outage_min_s): no outage yet. Binary-exact stamps.
  model.addPose(10.0, Eigen::Vector3d(0, 0, 0));
  model.addPose(10.25, Eigen::Vector3d(25, 0, 0));
  model.addPose(10.5, Eigen::Vector3d(50, 0, 0));
  EXPECT_EQ(model.outages(), 0);
  const double tilt = std::pow(0.2 * kDeg, 2);
  const double position = 0.03 * 0.03 + 0.1 * 0.1;  // 0.002 m/m over 50 m
  const double yaw = (1.0 + 0.25) * kDeg * kDeg;    // 0.01 deg/m over 50 m
  expectDiagonal(model.pose(), {position, position, position, tilt, tilt, yaw});
  // Outages of 3 s and 1 s (no step): (a T)^2 + (b T^2)^2 each on position, (c T)^2 on yaw;
  // tilt is gravity's and the twist is the IMU's.
  model.addPose(13.5, Eigen::Vector3d(50, 0, 0));
  model.addPose(14.5, Eigen::Vector3d(50, 0, 0));
  EXPECT_EQ(model.outages(), 2);
  const double outages = std::pow(0.01 * 3, 2) + std::pow(0.004 * 9, 2) +  // 3 s
                         std::pow(0.01 * 1, 2) + std::pow(0.004 * 1, 2);   // 1 s
  const double position2 = position + outages;
  const double yaw2 = yaw + (std::pow(0.02 * 3, 2) + std::pow(0.02 * 1, 2)) * kDeg * kDeg;
  expectDiagonal(model.pose(), {position2, position2, position2, tilt, tilt, yaw2});
  expectDiagonal(model.twist(), {1e-4, 1e-4, 1e-4, 6.25e-6, 2.5e-5, 1.6e-5});
  // The outages stay with the run: its output still carries their error.
  model.addPose(14.75, Eigen::Vector3d(50, 30, 0));
  EXPECT_NEAR(model.pose()[0], 0.03 * 0.03 + 0.16 * 0.16 + outages, 1e-15);
  // A new run starts from its own origin: the gap from the old run's last pose is no outage.
  model.startNewRun();
  EXPECT_EQ(model.outages(), 0);
  model.addPose(100.0, Eigen::Vector3d(0, 0, 0));
  EXPECT_EQ(model.outages(), 0);
  expectDiagonal(model.pose(), {9e-4, 9e-4, 9e-4, tilt, tilt, std::pow(kDeg, 2)});
}

TEST(OdometryCovariance, TheResetKeysItReplacedAreNamed) {
  for (const char* key : {"reset_position_sigma_m", "reset_yaw_sigma_deg"}) {
    const YamlReader yaml = YamlReader::fromString(
        std::string("odometry_covariance:\n  ") + key + ": 0.07\n", "robot.yaml");
    const std::string error =
        test::errorOf([&] { OdometryCovarianceOptions::load(yaml, "odometry_covariance"); });
    EXPECT_NE(error.find(std::string("robot.yaml: odometry_covariance.") + key +
                         " was replaced by outage_position_sigma_mps"),
              std::string::npos)
        << error;
  }
}

TEST(OdometryCovariance, ReadsItsSectionAndNamesABadKey) {
  const YamlReader yaml = YamlReader::fromString(
      "odometry_covariance:\n  position_drift: 0.004\n  velocity_sigma_mps: 0.05\n", "robot.yaml");
  const OdometryCovarianceOptions o = OdometryCovarianceOptions::load(yaml, "odometry_covariance");
  EXPECT_DOUBLE_EQ(o.position_drift, 0.004);
  EXPECT_EQ(o.velocity_sigma_mps, Eigen::Vector3d::Constant(0.05));  // one number: all axes
  EXPECT_DOUBLE_EQ(o.tilt_sigma_deg, OdometryCovarianceOptions().tilt_sigma_deg);
  for (const char* key :
       {"position_sigma_m", "yaw_drift_deg_per_m", "outage_min_s", "outage_position_sigma_mps",
        "outage_position_sigma_mps2", "outage_yaw_sigma_deg_per_s", "angular_rate_sigma_rps"}) {
    const YamlReader bad = YamlReader::fromString(
        std::string("odometry_covariance:\n  ") + key + ": -0.1\n", "robot.yaml");
    const std::string error =
        test::errorOf([&] { OdometryCovarianceOptions::load(bad, "odometry_covariance"); });
    EXPECT_NE(error.find("robot.yaml: odometry_covariance." + std::string(key)), std::string::npos)
        << error;
  }
}

TEST(OdometryCovariance, TheTwistsSigmasMayDifferPerAxis) {
  const YamlReader yaml = YamlReader::fromString(
      "odometry_covariance:\n  angular_rate_sigma_rps: [0.018, 0.05, 0.03]\n", "robot.yaml");
  OdometryCovarianceOptions o = OdometryCovarianceOptions::load(yaml, "odometry_covariance");
  EXPECT_EQ(o.angular_rate_sigma_rps, Eigen::Vector3d(0.018, 0.05, 0.03));
  EXPECT_EQ(o.velocity_sigma_mps, OdometryCovarianceOptions().velocity_sigma_mps);
  o.velocity_sigma_mps = Eigen::Vector3d(0.01, 0.02, 0.03);
  expectDiagonal(OdometryCovariance(o).twist(), {1e-4, 4e-4, 9e-4, 0.018 * 0.018, 0.0025, 9e-4});

  const std::pair<const char*, const char*> bad[] = {
      {"[0.018, 0.05]",
       "robot.yaml: key 'odometry_covariance.angular_rate_sigma_rps' must have 3 values"},
      {"[0.018, -0.05, 0.03]",
       "robot.yaml: odometry_covariance.angular_rate_sigma_rps[1] must be a "
       "finite value >= 0, got -0.05"},
      {"{x: 1}",
       "robot.yaml: key 'odometry_covariance.angular_rate_sigma_rps' must be a number or a list of "
       "3 numbers (x, y, z)"},
      {"[0.018, fast, 0.03]", "odometry_covariance.angular_rate_sigma_rps[1]"}};
  for (const auto& [value, message] : bad) {
    const YamlReader y = YamlReader::fromString(
        std::string("odometry_covariance:\n  angular_rate_sigma_rps: ") + value + "\n",
        "robot.yaml");
    const std::string error =
        test::errorOf([&] { OdometryCovarianceOptions::load(y, "odometry_covariance"); });
    EXPECT_NE(error.find(message), std::string::npos) << value << ": " << error;
  }
}

TEST(OdometryCovariance, ShippedConfigsGiveTheRealImuWiderSigmas) {
  const Config euroc = Config::load(test::sourcePath("config/euroc.yaml"));
  const Config real = Config::load(test::sourcePath("config/euroc_real.yaml"));
  const OdometryCovarianceOptions& s = euroc.odometry_covariance;
  const OdometryCovarianceOptions& r = real.odometry_covariance;
  EXPECT_GT(r.velocity_sigma_mps.minCoeff(), s.velocity_sigma_mps.maxCoeff());
  EXPECT_GT(r.angular_rate_sigma_rps.minCoeff(), s.angular_rate_sigma_rps.maxCoeff());
  EXPECT_GE(r.position_drift, s.position_drift);
  EXPECT_GT(s.position_sigma_m, 0.0);
  EXPECT_GT(s.yaw_sigma_deg, 0.0);
}
