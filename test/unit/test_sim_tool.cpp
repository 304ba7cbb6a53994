// The `alvio_sim` program end to end: the EuRoC folder it writes, byte-identical
// output for a seed, the real-IMU mode, rosbags and the benchmark cache.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "alvio/io/euroc_dataset.h"
#include "alvio/io/trajectory_io.h"
#include "test_support.h"

using namespace alvio;
namespace fs = std::filesystem;

namespace {

int run(const std::string& args, std::string* out) {
  return test::runCommand(std::string(ALVIO_BIN_DIR) + "/alvio_sim " + args, out);
}

// Every file under `dir` (relative path -> content).
std::map<std::string, std::string> snapshot(const std::string& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file())
      files[fs::relative(e.path(), dir).string()] = test::readFile(e.path().string());
  return files;
}

const char* kSmall = "--scene plain_room --trajectory figure8 --duration 0.6 --quiet ";

}  // namespace

TEST(SimTool, WritesAnEurocFolderThatTheDatasetReaderLoads) {
  const std::string dir = test::scratchDir() + "/seq";
  std::string out;
  ASSERT_EQ(run(std::string(kSmall) + "--out " + dir, &out), 0) << out;
  const EurocDataset d(dir);
  EXPECT_EQ(d.images().size(), 13u);  // 0.6 s at 20 Hz, both ends included
  ASSERT_TRUE(d.groundTruth().has_value());
  EXPECT_NEAR(static_cast<double>(d.imu().size()), 0.6 * 200 + 1, 1.0);
  EXPECT_EQ(d.groundTruth()->size(), d.imu().size());
  // IMU covers the frames; the ground truth carries the simulated biases.
  EXPECT_LE(d.imu().front().t_ns, d.images().front().t_ns);
  EXPECT_GE(d.imu().back().t_ns, d.images().back().t_ns);
  EXPECT_GT(d.groundTruth()->front().bg.norm(), 0.0);
  // The standstill at the start of built-in paths: the accelerometer reads gravity.
  EXPECT_NEAR(d.imu().front().acc.norm(), 9.81, 0.3);
  const auto cam = d.cameraCalibration();
  ASSERT_TRUE(cam.has_value());
  EXPECT_EQ(cam->width, 752);
  EXPECT_EQ(readTrajectory(dir + "/groundtruth.tum").size(), d.groundTruth()->size());
  EXPECT_TRUE(fs::exists(dir + "/sim_info.yaml"));
}

TEST(SimTool, SameSeedGivesByteIdenticalOutputAndAnotherSeedDoesNot) {
  const std::string base = test::scratchDir();
  std::string out;
  ASSERT_EQ(run(std::string(kSmall) + "--seed 7 --out " + base + "/a", &out), 0) << out;
  ASSERT_EQ(run(std::string(kSmall) + "--seed 7 --threads 1 --out " + base + "/b", &out), 0) << out;
  ASSERT_EQ(run(std::string(kSmall) + "--seed 8 --out " + base + "/c", &out), 0) << out;
  const auto a = snapshot(base + "/a"), b = snapshot(base + "/b"), c = snapshot(base + "/c");
  ASSERT_EQ(a.size(), b.size());
  for (const auto& [name, content] : a) {
    ASSERT_TRUE(b.count(name)) << name;
    EXPECT_TRUE(content == b.at(name)) << name << " differs between two runs with seed 7";
  }
  // Another seed: other sensor noise in the images and the IMU, the same ground truth poses.
  EXPECT_NE(a.at("mav0/imu0/data.csv"), c.at("mav0/imu0/data.csv"));
  int differing_images = 0;
  for (const auto& [name, content] : a)
    if (name.rfind("mav0/cam0/data/", 0) == 0 && content != c.at(name)) ++differing_images;
  EXPECT_EQ(differing_images, 13);
  EXPECT_EQ(a.at("mav0/cam0/data.csv"), c.at("mav0/cam0/data.csv"));
}

TEST(SimTool, RefusesToOverwriteAFolderItDidNotWrite) {
  const std::string dir = test::scratchDir() + "/real";
  fs::create_directories(dir + "/mav0/cam0");
  std::string out;
  EXPECT_NE(run(std::string(kSmall) + "--out " + dir, &out), 0);
  EXPECT_NE(out.find("refusing to overwrite"), std::string::npos) << out;
  EXPECT_TRUE(fs::exists(dir + "/mav0/cam0"));
}

TEST(SimTool, BadOptionsNameTheProblem) {
  std::string out;
  EXPECT_NE(run("--trajectory nowhere.txt --out /tmp/x --quiet", &out), 0);
  EXPECT_NE(out.find("nowhere.txt"), std::string::npos) << out;
  EXPECT_NE(run("--trajectory figure8 --texture shiny --out /tmp/x --quiet", &out), 0);
  EXPECT_NE(out.find("texture density"), std::string::npos) << out;
  EXPECT_NE(run("--trajectory figure8 --illumination gain=x --out /tmp/x --quiet", &out), 0);
  EXPECT_NE(out.find("'gain' needs a number"), std::string::npos) << out;
}

TEST(SimTool, WritesARosbag) {
  const std::string dir = test::scratchDir() + "/bagged";
  std::string out;
  ASSERT_EQ(run(std::string(kSmall) + "--bag --out " + dir, &out), 0) << out;
  const std::string bag = test::readFile(dir + "/bagged.bag");
  ASSERT_GT(bag.size(), 13u * 752 * 480);  // the raw images alone
  EXPECT_EQ(bag.substr(0, 13), "#ROSBAG V2.0\n");
  EXPECT_NE(bag.find("/cam0/image_raw"), std::string::npos);
  EXPECT_NE(bag.find("/imu0"), std::string::npos);
  EXPECT_NE(bag.find("sensor_msgs/Imu"), std::string::npos);
}

TEST(SimTool, RealImuModePairsRenderedImagesWithTheRealImuAndGroundTruth) {
  ALVIO_REQUIRE_SHARED_DATA(data);
  const std::string dir = test::scratchDir() + "/realimu";
  std::string out;
  ASSERT_EQ(run("--scene plain_room --trajectory MH_05 --imu real --start 10 --duration 0.5 "
                "--quiet --out " +
                    dir,
                &out),
            0)
      << out;
  const EurocDataset sim(dir);
  const std::string orb = data + "/euroc_imu_only_orbslam3_format/Examples/Monocular-Inertial/";
  const auto real_imu = readEurocImuCsv(orb + "EuRoC_IMU/MH05.txt");
  ASSERT_FALSE(sim.imu().empty());
  // The IMU samples are the real ones, unchanged.
  std::size_t k = 0;
  while (real_imu[k].t_ns < sim.imu().front().t_ns) ++k;
  for (const auto& m : sim.imu()) {
    ASSERT_EQ(m.t_ns, real_imu[k].t_ns);
    EXPECT_EQ(m.acc, real_imu[k].acc);
    EXPECT_EQ(m.gyr, real_imu[k].gyr);
    ++k;
  }
  // The frames are at real cam0 stamps.
  std::ifstream stamps(orb + "EuRoC_TimeStamps/MH05.txt");
  std::set<int64_t> real_stamps;
  for (int64_t t; stamps >> t;) real_stamps.insert(t);
  for (const auto& img : sim.images()) EXPECT_TRUE(real_stamps.count(img.t_ns)) << img.t_ns;
  // The ground truth is the real one (with its biases).
  const auto real_gt = readEurocGroundTruthCsv(
      data +
      "/euroc_groundtruth/vins_mono_benchmark_publisher/benchmark_publisher/config/"
      "MH_05_difficult/data.csv");
  const auto& gt = *sim.groundTruth();
  ASSERT_FALSE(gt.empty());
  std::size_t j = 0;
  while (real_gt[j].t_ns < gt.front().t_ns) ++j;
  EXPECT_EQ(gt.front().t_ns, real_gt[j].t_ns);
  EXPECT_LT((gt.front().p - real_gt[j].p).norm(), 1e-6);
  EXPECT_LT((gt.front().ba - real_gt[j].ba).norm(), 1e-6);
}

TEST(SimTool, BenchmarkSequencesAreCachedAndRebuiltWhenTheirInputsChange) {
  ALVIO_REQUIRE_SHARED_DATA(data);
  const std::string dir = test::scratchDir() + "/bench";
  const std::string args =
      "--scene plain_room --duration 0.3 --quiet --benchmark " + dir + " --only sim_MH_05 ";
  std::string out;
  ASSERT_EQ(run(args, &out), 0) << out;
  EXPECT_NE(out.find("sim_MH_05: 6 frames over"), std::string::npos) << out;
  ASSERT_EQ(run(args, &out), 0) << out;
  EXPECT_NE(out.find("sim_MH_05: up to date"), std::string::npos) << out;
  ASSERT_EQ(run(args + "--seed 3", &out), 0) << out;
  EXPECT_NE(out.find("sim_MH_05: 6 frames over"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir + "/sim_MH_01"));
  EXPECT_NE(run(args + "--only sim_MH_99", &out), 0);
  EXPECT_NE(out.find("unknown benchmark sequence 'sim_MH_99'"), std::string::npos) << out;
}
