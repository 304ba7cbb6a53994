#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "alvio/common/error.h"
#include "alvio/io/euroc_dataset.h"
#include "alvio/io/trajectory_io.h"
#include "test_support.h"

using namespace alvio;
using test::errorOf;

namespace {
std::string writeFile(const std::string& name, const std::string& text) {
  const std::string path = test::scratchDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}
}  // namespace

TEST(TrajectoryIo, TumRoundTrip) {
  Trajectory traj;
  for (int i = 0; i < 50; ++i) {
    StampedPose p;
    p.t = 1403636580.0 + 0.05 * i;
    p.p = Eigen::Vector3d(i * 0.1, -i * 0.2, 0.3);
    p.q = Eigen::Quaterniond(Eigen::AngleAxisd(0.02 * i, Eigen::Vector3d(1, 2, 3).normalized()));
    traj.push_back(p);
  }
  const std::string path = test::scratchDir() + "/t.tum";
  writeTumTrajectory(path, traj);
  EXPECT_EQ(detectTrajectoryFormat(path), TrajectoryFormat::kTum);
  const Trajectory back = readTrajectory(path);
  ASSERT_EQ(back.size(), traj.size());
  for (std::size_t i = 0; i < traj.size(); ++i) {
    EXPECT_NEAR(back[i].t, traj[i].t, 1e-6);
    EXPECT_LT((back[i].p - traj[i].p).norm(), 1e-9);
    EXPECT_LT(back[i].q.angularDistance(traj[i].q), 1e-8);
  }
}

TEST(TrajectoryIo, FormatsAreDetected) {
  const auto euroc =
      writeFile("gt.csv",
                "#timestamp, p_x, p_y, p_z, q_w, q_x, q_y, q_z\n"
                "1403638519492829440,4.46,-1.68,0.58,0.238261,-0.757610,-0.348629,-0.497711\n");
  const auto vins = writeFile("vins.csv",
                              "1403638523377829632,-0.00978,-0.03525,0.09381,-0.05507,0.80043,"
                              "0.01311,0.59675,-0.07,-0.06,-0.61,\n");
  EXPECT_EQ(detectTrajectoryFormat(euroc), TrajectoryFormat::kEuroc);
  EXPECT_EQ(detectTrajectoryFormat(vins), TrajectoryFormat::kVinsMono);
  const Trajectory a = readTrajectory(euroc);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_NEAR(a[0].t, 1403638519.492829440, 1e-6);
  EXPECT_NEAR(a[0].q.w(), 0.238261, 1e-5);  // w-first in CSV
  EXPECT_NEAR(a[0].q.x(), -0.757610, 1e-5);
  const Trajectory b = readTrajectory(vins);
  EXPECT_NEAR(b[0].q.w(), -0.05507, 1e-4);
  EXPECT_NEAR(b[0].p.z(), 0.09381, 1e-12);
}

TEST(TrajectoryIo, MalformedLineNamesFileAndLine) {
  const auto path = writeFile("bad.tum",
                              "# t x y z qx qy qz qw\n"
                              "1.0 0 0 0 0 0 0 1\n"
                              "2.0 0 0 zero 0 0 0 1\n");
  const std::string msg = errorOf([&] { readTrajectory(path); });
  EXPECT_NE(msg.find(path + ":3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("zero"), std::string::npos) << msg;
}

TEST(TrajectoryIo, WrongColumnCountIsAnError) {
  const auto path = writeFile("cols.tum", "1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 1\n");
  EXPECT_NE(errorOf([&] { readTrajectory(path, TrajectoryFormat::kTum); }).find(":2"),
            std::string::npos);
}

TEST(TrajectoryIo, NonUnitQuaternionIsAnError) {
  const auto path = writeFile("q.tum", "1.0 0 0 0 0.5 0.5 0.5 0.1\n");
  EXPECT_NE(errorOf([&] { readTrajectory(path); }).find("quaternion"), std::string::npos);
}

TEST(TrajectoryIo, UnsortedAndDuplicateStampsAreReported) {
  const auto path = writeFile("order.tum",
                              "1.0 0 0 0 0 0 0 1\n"
                              "3.0 0 0 0 0 0 0 1\n"
                              "2.0 0 0 0 0 0 0 1\n"
                              "3.0 1 0 0 0 0 0 1\n");
  const std::string msg = errorOf([&] { readTrajectory(path); });
  EXPECT_NE(msg.find(path + ":3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("earlier"), std::string::npos) << msg;
  // The lenient policy sorts and drops the duplicate, keeping the first.
  const Trajectory t =
      readTrajectory(path, TrajectoryFormat::kAuto, TimeOrderPolicy::kSortAndDedup);
  ASSERT_EQ(t.size(), 3u);
  EXPECT_DOUBLE_EQ(t[1].t, 2.0);
  EXPECT_DOUBLE_EQ(t[2].p.x(), 0.0);
}

TEST(EurocDataset, WriteThenReadRoundTrip) {
  namespace fs = std::filesystem;
  const std::string root = test::scratchDir();
  const fs::path mav0 = fs::path(root) / "mav0";
  fs::create_directories(mav0 / "cam0" / "data");
  fs::create_directories(mav0 / "imu0");
  fs::create_directories(mav0 / "state_groundtruth_estimate0");
  writeEurocImageCsv((mav0 / "cam0" / "data.csv").string(), {100, 200, 300});
  std::vector<ImuSample> imu(5);
  for (int i = 0; i < 5; ++i) {
    imu[i].t_ns = 100 + 5 * i;
    imu[i].gyr = Eigen::Vector3d(0.1 * i, 0.2, 1e-7 / 3);
    imu[i].acc = Eigen::Vector3d(9.81, -0.5 * i, 1.0 / 3);
  }
  writeEurocImuCsv((mav0 / "imu0" / "data.csv").string(), imu);
  GroundTruth gt(2);
  gt[0].t_ns = 100;
  gt[1].t_ns = 200;
  gt[1].p = Eigen::Vector3d(1, 2, 3);
  gt[1].v = Eigen::Vector3d(0.5, 0, 0);
  gt[1].ba = Eigen::Vector3d(0.01, 0.02, 0.03);
  writeEurocGroundTruthCsv((mav0 / "state_groundtruth_estimate0" / "data.csv").string(), gt);
  CameraOptions cam;
  cam.T_b_c.translation() = Eigen::Vector3d(0.1, 0.2, 0.3);
  writeEurocCameraYaml((mav0 / "cam0" / "sensor.yaml").string(), cam);
  writeEurocImuYaml((mav0 / "imu0" / "sensor.yaml").string(), ImuOptions());

  EurocDataset ds(root);
  ASSERT_EQ(ds.images().size(), 3u);
  EXPECT_EQ(ds.images()[1].t_ns, 200);
  EXPECT_EQ(fs::path(ds.images()[1].path).filename(), "200.png");
  ASSERT_EQ(ds.imu().size(), 5u);
  EXPECT_EQ(ds.imu()[4].acc, imu[4].acc);  // %.17g is exact
  EXPECT_EQ(ds.imu()[4].gyr, imu[4].gyr);
  ASSERT_TRUE(ds.groundTruth().has_value());
  EXPECT_NEAR((ds.groundTruth()->at(1).ba - gt[1].ba).norm(), 0, 1e-9);
  const auto cam_back = ds.cameraCalibration();
  ASSERT_TRUE(cam_back.has_value());
  EXPECT_TRUE(cam_back->T_b_c.isApprox(cam.T_b_c, 1e-12));
  EXPECT_EQ(cam_back->intrinsics, cam.intrinsics);
}

TEST(EurocDataset, MissingFolderAndFilesAreNamed) {
  EXPECT_NE(errorOf([] { EurocDataset ds("/nonexistent/euroc"); }).find("/nonexistent/euroc"),
            std::string::npos);
  const std::string root = test::scratchDir();
  std::filesystem::create_directories(root + "/mav0/cam0");
  EXPECT_NE(errorOf([&] { EurocDataset ds(root); }).find("cam0/data.csv"), std::string::npos);
}

TEST(EurocDataset, BadImuLineNamesFileAndLine) {
  const auto path = writeFile("imu.csv",
                              "#t,wx,wy,wz,ax,ay,az\n"
                              "100,0,0,0,0,0,9.8\n"
                              "105,0,0,0,0,9.8\n");
  const std::string msg = errorOf([&] { readEurocImuCsv(path); });
  EXPECT_NE(msg.find(path + ":3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("7 columns"), std::string::npos) << msg;
}

TEST(EurocDataset, RealMicroDatasetReads) {
  ALVIO_REQUIRE_SHARED_DATA(shared);
  EurocDataset ds(shared + "/euroc_V1_01_easy_micro_kimera");
  EXPECT_EQ(ds.images().size(), 95u);
  EXPECT_EQ(ds.imu().size(), 29120u);
  EXPECT_EQ(ds.images().front().t_ns, 1403715273262142976LL);
  EXPECT_TRUE(std::filesystem::exists(ds.images().front().path));
  EXPECT_FALSE(ds.groundTruth().has_value());
  // Hovering on the floor: the specific force is gravity.
  EXPECT_NEAR(ds.imu().front().acc.norm(), 9.81, 0.2);
}

TEST(EurocDataset, RealGroundTruthCsvReads) {
  ALVIO_REQUIRE_SHARED_DATA(shared);
  const GroundTruth gt = readEurocGroundTruthCsv(
      shared +
      "/euroc_groundtruth/vins_mono_benchmark_publisher/benchmark_publisher/config/"
      "MH_05_difficult/data.csv");
  ASSERT_GT(gt.size(), 20000u);
  EXPECT_EQ(gt.front().t_ns, 1403638519492829440LL);
  EXPECT_NEAR(gt.front().ba.y(), 0.124837, 1e-9);
  // The same poses as the TUM copy.
  const Trajectory tum =
      readTrajectory(shared + "/euroc_groundtruth/xygxgn_VINS-Fusion/output/MH_05_difficult.txt");
  EXPECT_NEAR((tum.front().p - gt.front().p).norm(), 0, 1e-6);
  EXPECT_LT(tum.front().q.angularDistance(gt.front().q), 1e-5);
}
