// camera.timeshift_cam_imu end to end: images stamped on a camera clock that runs off the IMU's
// are put back on the IMU's clock by the shift. On 8 s of a rendered figure eight whose image
// stamps are moved by +-30 ms, the shift gives back the unmoved run's trajectory exactly, and
// without it the error grows.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "alvio/config/config.h"
#include "test_support.h"

using namespace alvio;
namespace fs = std::filesystem;

namespace {

std::string bin(const std::string& tool) {
  return std::string(ALVIO_BIN_DIR) + "/" + tool + " ";
}

// Rendered once for all the tests here (about 8 s on two cores).
const std::string& sequence() {
  static const std::string dir = [] {
    const std::string d = test::sharedScratchDir("figure8");
    std::string out;
    if (test::runCommand(bin("alvio_sim") + "--trajectory figure8 --duration 8 --quiet --out " + d,
                         &out) != 0)
      ADD_FAILURE() << "alvio_sim failed:\n" << out;
    return d;
  }();
  return dir;
}

// The sequence with every image stamped `camera_late_ns` later (images, IMU and ground truth
// shared through links): a camera clock running behind the IMU's, for which Kalibr's
// timeshift_cam_imu is -camera_late_ns.
std::string withImagesStampedLater(int64_t camera_late_ns, const std::string& name) {
  const fs::path from = fs::path(sequence()) / "mav0";
  const fs::path to = fs::path(test::sharedScratchDir(name)) / "mav0";
  fs::create_directories(to / "cam0");
  fs::create_directory_symlink(from / "imu0", to / "imu0");
  fs::create_directory_symlink(from / "state_groundtruth_estimate0",
                               to / "state_groundtruth_estimate0");
  fs::create_directory_symlink(from / "cam0" / "data", to / "cam0" / "data");
  std::ifstream in(from / "cam0" / "data.csv");
  std::ostringstream out;
  std::string line;
  int images = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') {
      out << line << "\n";
      continue;
    }
    const std::size_t comma = line.find(',');
    out << std::stoll(line.substr(0, comma)) + camera_late_ns << line.substr(comma) << "\n";
    ++images;
  }
  EXPECT_GT(images, 100);
  test::writeFile((to / "cam0" / "data.csv").string(), out.str());
  return to.parent_path().string();
}

struct RunOutput {
  int rc = -1;
  std::string output, trajectory;
  double ate = -1;
};

RunOutput run(const std::string& dataset, const std::string& set, const std::string& name) {
  RunOutput r;
  const std::string out = test::sharedScratchDir("run_" + name);
  r.rc = test::runCommand(bin("alvio_run") + "--quiet --no-log --dataset " + dataset + " --out " +
                              out + (set.empty() ? "" : " --set " + set),
                          &r.output);
  r.trajectory = test::readFile(out + "/trajectory.tum");
  std::smatch m;
  if (std::regex_search(r.output, m, std::regex(R"(ATE_RMSE=([0-9.]+))"))) r.ate = std::stod(m[1]);
  return r;
}

const RunOutput& unmoved() {
  static const RunOutput r = run(sequence(), "", "unmoved");
  return r;
}

}  // namespace

TEST(CameraTimeShift, TheShiftPutsLateOrEarlyImagesBackOnTheImuClock) {
  ASSERT_EQ(unmoved().rc, 0) << unmoved().output;
  ASSERT_GT(unmoved().trajectory.size(), 1000u);
  for (const int64_t late_ms : {30, -30}) {
    SCOPED_TRACE("images stamped " + std::to_string(late_ms) + " ms late");
    const std::string moved =
        withImagesStampedLater(late_ms * 1000000, "late" + std::to_string(late_ms));
    const RunOutput shifted =
        run(moved, "camera.timeshift_cam_imu=" + std::to_string(-late_ms * 1e-3),
            "shifted" + std::to_string(late_ms));
    ASSERT_EQ(shifted.rc, 0) << shifted.output;
    // Same images at the same IMU-clock times: the same run, stamps and poses to the digit.
    EXPECT_EQ(shifted.trajectory, unmoved().trajectory);
    EXPECT_EQ(shifted.ate, unmoved().ate);
  }
}

TEST(CameraTimeShift, LeftUncorrectedTheOffsetRaisesTheError) {
  const std::string moved = withImagesStampedLater(30000000, "late_uncorrected");
  const RunOutput uncorrected = run(moved, "", "uncorrected");
  ASSERT_EQ(unmoved().rc, 0) << unmoved().output;
  ASSERT_EQ(uncorrected.rc, 0) << uncorrected.output;
  ASSERT_GT(unmoved().ate, 0);
  // Measured 10.7x (5.7 mm against 60.7 mm; docs/benchmarks.md, sixty-ninth session).
  EXPECT_GT(uncorrected.ate, 3 * unmoved().ate)
      << "unmoved " << unmoved().ate << " m, 30 ms late uncorrected " << uncorrected.ate << " m";
}

TEST(CameraTimeShift, AShiftBeyondASecondIsRefusedByName) {
  const std::string config = test::writeFile(
      test::scratchDir() + "/far.yaml",
      "base: " + test::sourcePath("config/euroc.yaml") + "\ncamera:\n  timeshift_cam_imu: 1.5\n");
  const std::string msg = test::errorOf([&] { Config::load(config); });
  EXPECT_NE(msg.find("camera.timeshift_cam_imu"), std::string::npos) << msg;
  EXPECT_NE(msg.find("1.5"), std::string::npos) << msg;
}

TEST(CameraTimeShift, ImuClockRoundsToTheNearestNanosecond) {
  CameraOptions camera;
  camera.timeshift_cam_imu = -0.0123456789;
  EXPECT_EQ(camera.imuClockNs(1000000000), 1000000000 - 12345679);
  camera.timeshift_cam_imu = 0;
  EXPECT_EQ(camera.imuClockNs(42), 42);
}
