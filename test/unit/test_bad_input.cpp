// Bad input gives a clear error (naming the file, key or line) before any processing,
// or is skipped with a count: configs, EuRoC folders, CSVs, images.
#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "alvio/common/error.h"
#include "alvio/common/log_throttle.h"
#include "alvio/config/config.h"
#include "alvio/config/yaml_reader.h"
#include "alvio/io/euroc_dataset.h"
#include "alvio/io/trajectory_io.h"
#include "alvio/pipeline/offline_runner.h"
#include "test_support.h"

using namespace alvio;
using test::errorOf;
namespace fs = std::filesystem;

namespace {

#define EXPECT_MENTIONS(message, fragment)               \
  EXPECT_NE((message).find(fragment), std::string::npos) \
      << "'" << (message) << "' lacks '" << (fragment) << "'"

// The default config with `from` replaced by `to`, written to dir/name.
std::string configReplacing(const std::string& dir, const std::string& from,
                            const std::string& to) {
  std::string text = test::readFile(test::sourcePath("config/euroc.yaml"));
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  if (pos != std::string::npos) text.replace(pos, from.size(), to);
  return test::writeFile(dir + "/config.yaml", text);
}

// A small EuRoC folder: `count` textured images of width x height at 20 Hz and a still,
// level IMU at 200 Hz over the same time.
std::string makeEurocFolder(const std::string& root, int count, int width, int height,
                            int64_t t0 = 1'000'000'000'000) {
  const fs::path cam = fs::path(root) / "mav0" / "cam0";
  fs::create_directories(cam / "data");
  fs::create_directories(fs::path(root) / "mav0" / "imu0");
  std::vector<int64_t> stamps;
  std::mt19937 rng(7);
  for (int i = 0; i < count; ++i) {
    const int64_t t = t0 + i * 50'000'000;
    stamps.push_back(t);
    cv::Mat image(height, width, CV_8UC1);
    cv::randu(image, 0, 255);
    cv::imwrite((cam / "data" / (std::to_string(t) + ".png")).string(), image);
  }
  writeEurocImageCsv((cam / "data.csv").string(), stamps);
  std::vector<ImuSample> imu;
  for (int64_t t = t0 - 100'000'000; t <= stamps.back() + 100'000'000; t += 5'000'000) {
    ImuSample s;
    s.t_ns = t;
    s.acc = {0, 0, 9.81};
    imu.push_back(s);
  }
  writeEurocImuCsv((fs::path(root) / "mav0" / "imu0" / "data.csv").string(), imu);
  return root;
}

Config defaultConfig() {
  return Config::load(test::sourcePath("config/euroc.yaml"));
}

RunOptions quietRun(const std::string& out) {
  RunOptions o;
  o.out_dir = out;
  o.progress = false;
  return o;
}

}  // namespace

// --- configuration -------------------------------------------------------------------

TEST(BadConfig, NonInvertibleExtrinsicNamesKeyAndDeterminant) {
  // A rank-deficient rotation block (first row zero): T_b_c has no inverse.
  const std::string path = configReplacing(
      test::scratchDir(), "data: [0.0148655429818, -0.999880929698, 0.00414029679422,",
      "data: [0.0, 0.0, 0.0,");
  const std::string msg = errorOf([&] { Config::load(path); });
  EXPECT_MENTIONS(msg, path);
  EXPECT_MENTIONS(msg, "camera.T_BS");
  EXPECT_MENTIONS(msg, "not invertible");
  EXPECT_MENTIONS(msg, "det = ");
}

TEST(BadConfig, WrongTypeNamesKeyAndValue) {
  const std::string dir = test::scratchDir();
  std::string msg = errorOf([&] {
    Config::load(configReplacing(dir, "resolution: [752, 480]", "resolution: [752, tall]"));
  });
  EXPECT_MENTIONS(msg, "camera.resolution[1]");
  EXPECT_MENTIONS(msg, "tall");
  msg = errorOf([&] {
    Config::load(configReplacing(dir, "intrinsics: [458.654, 457.296, 367.215, 248.375]",
                                 "intrinsics: pinhole"));
  });
  EXPECT_MENTIONS(msg, "camera.intrinsics");
  EXPECT_MENTIONS(msg, "list");
}

// fuzz_config found this one: a resolution beyond int's range was undefined behaviour.
TEST(BadConfig, ResolutionOutOfRangeNamesKeyAndValue) {
  const std::string dir = test::scratchDir();
  for (const char* bad :
       {"resolution: [6e81, 480]", "resolution: [752, -480]", "resolution: [752.5, 480]"}) {
    const std::string msg =
        errorOf([&] { Config::load(configReplacing(dir, "resolution: [752, 480]", bad)); });
    EXPECT_MENTIONS(msg, "camera.resolution");
    EXPECT_MENTIONS(msg, "whole numbers");
  }
}

TEST(BadConfig, NegativeNoiseNamesKeyAndValue) {
  const std::string path =
      configReplacing(test::scratchDir(), "gyroscope_noise_density: 1.6968e-04",
                      "gyroscope_noise_density: -1.6968e-04");
  const std::string msg = errorOf([&] { Config::load(path); });
  EXPECT_MENTIONS(msg, "imu.gyroscope_noise_density");
  EXPECT_MENTIONS(msg, "-0.00016968");
}

TEST(BadConfig, ImageSizeDisagreeingWithCameraFailsBeforeProcessing) {
  const std::string dir = test::scratchDir();
  const std::string data = makeEurocFolder(dir + "/data", 4, 640, 480);
  EurocSource source(data);
  const Config config = defaultConfig();
  const std::string msg = errorOf([&] { runOffline(source, config, quietRun(dir + "/out")); });
  EXPECT_MENTIONS(msg, "camera.resolution");
  EXPECT_MENTIONS(msg, "[752, 480]");
  EXPECT_MENTIONS(msg, "640x480");
  // Nothing was processed, so nothing was written.
  EXPECT_FALSE(fs::exists(dir + "/out/trajectory.tum"));
}

// --- datasets --------------------------------------------------------------------------

TEST(BadDataset, MissingFolderIsNamed) {
  const std::string missing = test::scratchDir() + "/no_such_sequence";
  EXPECT_MENTIONS(errorOf([&] { EurocDataset ds(missing); }), missing);
  // A folder that exists but is not EuRoC.
  const std::string empty = test::scratchDir() + "/empty";
  fs::create_directories(empty);
  const std::string msg = errorOf([&] { EurocSource source(empty); });
  EXPECT_MENTIONS(msg, empty);
  EXPECT_MENTIONS(msg, "mav0");
}

TEST(BadDataset, CsvWithBadLineNamesFileAndLine) {
  const std::string dir = test::scratchDir();
  const std::string csv = test::writeFile(dir + "/imu.csv",
                                          "#timestamp [ns],wx,wy,wz,ax,ay,az\n"
                                          "1000,0,0,0,0,0,9.81\n"
                                          "2000,0,0,zero,0,0,9.81\n");
  std::string msg = errorOf([&] { readEurocImuCsv(csv); });
  EXPECT_MENTIONS(msg, csv + ":3");
  EXPECT_MENTIONS(msg, "'zero'");
  // A line cut short (as by a full disk) is named the same way.
  test::writeFile(csv, "1000,0,0,0,0,0,9.81\n2000,0,0\n");
  msg = errorOf([&] { readEurocImuCsv(csv); });
  EXPECT_MENTIONS(msg, csv + ":2");
  EXPECT_MENTIONS(msg, "7 columns");
  test::writeFile(dir + "/cam.csv", "#t,file\n1000,a.png\nnot-a-stamp,b.png\n");
  msg = errorOf([&] { readEurocImageCsv(dir + "/cam.csv", dir); });
  EXPECT_MENTIONS(msg, "cam.csv:3");
  EXPECT_MENTIONS(msg, "not-a-stamp");
}

// Rounding a fractional stamp at the int64 limit overflowed (UBSan in fuzz_euroc_csv).
TEST(BadDataset, StampAtTheInt64LimitIsAnErrorNotAnOverflow) {
  const std::string dir = test::scratchDir();
  const std::string csv = test::writeFile(dir + "/cam.csv", "9223372036854775807.9,a.png\n");
  const std::string msg = errorOf([&] { readEurocImageCsv(csv, dir); });
  EXPECT_MENTIONS(msg, csv + ":1");
  EXPECT_MENTIONS(msg, "not an integer");
  // Fractional stamps round half away from zero, also below zero.
  test::writeFile(csv, "-0.7,a.png\n1.5,b.png\n");
  const auto records = readEurocImageCsv(csv, dir);
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[0].t_ns, -1);
  EXPECT_EQ(records[1].t_ns, 2);
}

// Found by fuzz_tum_trajectory: a stamp beyond the int64 ns range wrapped and an
// out-of-order file was accepted by the strict reader.
TEST(BadDataset, TumStampBeyondNanosecondRangeIsAnError) {
  const std::string tum =
      test::writeFile(test::scratchDir() + "/traj.txt",
                      "14037152575.3 0 0 0 0 0 0 1\n1403715274.3 0 0 0 0 0 0 1\n");
  const std::string msg = errorOf([&] { readTrajectory(tum, TrajectoryFormat::kTum); });
  EXPECT_MENTIONS(msg, tum + ":1");
  EXPECT_MENTIONS(msg, "14037152575.3");
}

TEST(BadDataset, TruncatedPngIsSkippedAndCounted) {
  const std::string dir = test::scratchDir();
  const std::string data = makeEurocFolder(dir + "/data", 5, 752, 480);
  // Cut the third image in half, as an interrupted copy would.
  std::vector<fs::path> pngs;
  for (const auto& e : fs::directory_iterator(data + "/mav0/cam0/data")) pngs.push_back(e.path());
  std::sort(pngs.begin(), pngs.end());
  ASSERT_EQ(pngs.size(), 5u);
  fs::resize_file(pngs[2], fs::file_size(pngs[2]) / 2);
  // And make the fourth not a PNG at all.
  test::writeFile(pngs[3].string(), "this is not an image");

  EurocSource source(data);
  const RunResult r = runOffline(source, defaultConfig(), quietRun(dir + "/out"));
  EXPECT_EQ(r.skipped_images, 2u);
  EXPECT_EQ(r.frames, 3u);
  const auto summary = nlohmann::json::parse(test::readFile(dir + "/out/summary.json"));
  EXPECT_EQ(summary["skipped_images"], 2);
  EXPECT_EQ(summary["frames"], 3);
}

TEST(BadDataset, ImagesShiftedBeforeTheClocksZeroAreSkippedAndCounted) {
  // Images from 0.12 s on a clock that starts at 0 (simulated time), stamped 0.2 s late.
  const std::string dir = test::scratchDir();
  const std::string data = makeEurocFolder(dir + "/data", 5, 752, 480, 120'000'000);
  Config config = defaultConfig();
  config.camera.timeshift_cam_imu = -0.2;
  EurocSource source(data);
  const RunResult r = runOffline(source, config, quietRun(dir + "/out"));
  EXPECT_EQ(r.skipped_images, 2u);  // at -0.08 and -0.03 s on the IMU's clock
  EXPECT_EQ(r.frames, 3u);
}

// --- starting mid-way ---------------------------------------------------------------------

TEST(RunStart, SkipsTheDataBeforeTheStartAndRefusesANegativeOne) {
  const std::string dir = test::scratchDir();
  // Images every 50 ms from t0; the IMU from t0 - 0.1 s, so the start counts from there.
  const std::string data = makeEurocFolder(dir + "/data", 10, 752, 480);
  RunOptions o = quietRun(dir + "/out");
  o.start_s = 0.32;  // up to t0 + 0.22 s: the images at t0 + 0.25 .. 0.45 s stay
  EurocSource source(data);
  const RunResult r = runOffline(source, defaultConfig(), o);
  EXPECT_EQ(r.frames, 5u);
  EXPECT_EQ(r.skipped_images, 0u);  // skipped before the start is not "skipped" (unreadable)

  o.start_s = -1;
  EurocSource again(data);
  const std::string msg = errorOf([&] { runOffline(again, defaultConfig(), o); });
  EXPECT_MENTIONS(msg, "start must be >= 0 s");
}

// --- starting still ----------------------------------------------------------------------

// The real V1_01 start: the MAV sits on the floor for the 4.7 s of frames (with real IMU
// vibration). The estimator must say it is waiting, publish no pose, and so not drift.
TEST(StillStart, WaitsForMotionAndPublishesNoPose) {
  ALVIO_REQUIRE_SHARED_DATA(shared);
  const std::string data = shared + "/euroc_V1_01_easy_micro_kimera";
  if (!fs::exists(data + "/mav0")) GTEST_SKIP() << data << " missing: skipping";
  const std::string out = test::scratchDir() + "/out";
  EurocSource source(data);
  const RunResult r = runOffline(source, defaultConfig(), quietRun(out));
  EXPECT_EQ(r.frames, 95u);
  EXPECT_EQ(r.poses, 0u) << "a pose was published while standing still";
  EXPECT_FALSE(r.initialization.has_value());
  const std::string events = test::readFile(out + "/events.log");
  EXPECT_MENTIONS(events, " waiting ");
  EXPECT_EQ(events.find(" initialized "), std::string::npos) << events;
  // The waiting reasons say why: no excitation or no parallax, i.e. no motion.
  EXPECT_TRUE(events.find("excitation") != std::string::npos ||
              events.find("parallax") != std::string::npos)
      << events;
  const auto summary = nlohmann::json::parse(test::readFile(out + "/summary.json"));
  EXPECT_EQ(summary["poses"], 0);
}

// fuzz_config found this one: a complex (non-scalar) mapping key made unknownKeys() throw
// from a path that must not, which terminated the program.
TEST(BadConfig, ComplexKeyIsReportedAsUnknownWithoutThrowing) {
  const YamlReader yaml =
      YamlReader::fromString("camera:\n  ? [a, b]\n  : 1\n  rate_hz: 20\n", "complex.yaml");
  EXPECT_EQ(yaml.getDouble("camera.rate_hz"), 20.0);
  std::vector<std::string> unknown;
  EXPECT_NO_THROW(unknown = yaml.unknownKeys());
  ASSERT_EQ(unknown.size(), 1u);
  EXPECT_MENTIONS(unknown[0], "camera.");
  EXPECT_NO_THROW(yaml.warnUnknownKeys());
}

// --- broken streams (what a bag or driver delivers on a bad day) -------------------------

namespace {

// Messages as given, in the given order: a recorded stream with faults in it.
class ListSource : public SensorSource {
 public:
  explicit ListSource(std::vector<SensorMessage> messages) : messages_(std::move(messages)) {
    for (const auto& m : messages_) images_ += m.kind == SensorMessage::Kind::kImage;
  }
  bool next(SensorMessage* m) override {
    if (i_ >= messages_.size()) return false;
    *m = messages_[i_++];
    return true;
  }
  std::size_t imageCount() const override { return images_; }
  std::string description() const override { return "test stream"; }

 private:
  std::vector<SensorMessage> messages_;
  std::size_t i_ = 0, images_ = 0;
};

SensorMessage imuAt(int64_t t_ns, double acc_z = 9.81) {
  SensorMessage m;
  m.kind = SensorMessage::Kind::kImu;
  m.t_ns = m.imu.t_ns = t_ns;
  m.imu.acc = {0, 0, acc_z};
  return m;
}

SensorMessage imageAt(int64_t t_ns) {
  SensorMessage m;
  m.kind = SensorMessage::Kind::kImage;
  m.t_ns = t_ns;
  m.load_image = [t_ns] {
    cv::Mat image(480, 752, CV_8UC1);
    cv::theRNG().state = static_cast<uint64_t>(t_ns);
    cv::randu(image, 0, 255);
    return image;
  };
  return m;
}

}  // namespace

TEST(BadStream, NonFiniteAndOutOfOrderMessagesAreDroppedAndCounted) {
  const int64_t t0 = 1'000'000'000'000, imu_dt = 5'000'000, frame_dt = 50'000'000;
  std::vector<SensorMessage> messages;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  int expected_imu_drops = 0;
  for (int i = 0; i <= 200; ++i) {
    const int64_t t = t0 + i * imu_dt;
    if (i % 10 == 0) messages.push_back(imageAt(t));
    if (i >= 50 && i < 60) {  // a NaN burst, then Inf
      messages.push_back(imuAt(t, i < 55 ? nan : std::numeric_limits<double>::infinity()));
      ++expected_imu_drops;
    } else {
      messages.push_back(imuAt(t));
    }
    if (i == 100 || i == 101) {  // a duplicate stamp, and a sample from the past
      messages.push_back(imuAt(i == 100 ? t : t - 20 * imu_dt));
      ++expected_imu_drops;
    }
  }
  // Two images stamped back in time, as a glitching driver would send them.
  messages.insert(messages.begin() + messages.size() / 2, imageAt(t0 + frame_dt / 2));
  messages.insert(messages.begin() + messages.size() / 2 + 5, imageAt(t0 + 3 * frame_dt));

  ListSource source(messages);
  const std::string out = test::scratchDir() + "/out";
  const RunResult r = runOffline(source, defaultConfig(), quietRun(out));
  EXPECT_EQ(r.dropped_imu, static_cast<std::size_t>(expected_imu_drops));
  EXPECT_EQ(r.dropped_images, 2u);
  EXPECT_EQ(r.frames, 21u);  // every in-order image, none of the two from the past
  for (const auto& p : r.trajectory) EXPECT_TRUE(p.p.allFinite() && p.q.coeffs().allFinite());
  const auto summary = nlohmann::json::parse(test::readFile(out + "/summary.json"));
  EXPECT_EQ(summary["dropped_imu"], expected_imu_drops);
  EXPECT_EQ(summary["dropped_images"], 2);
}

TEST(BadStream, ClockJumpBackResetsAndContinuesOnTheNewClock) {
  const int64_t t0 = 1'000'000'000'000, imu_dt = 5'000'000, back = 500'000'000;
  std::vector<SensorMessage> messages;
  for (int i = 0; i <= 400; ++i) {  // 2 s; from 1 s on every stamp is 0.5 s earlier
    const int64_t t = t0 + i * imu_dt - (i >= 200 ? back : 0);
    if (i % 10 == 0) messages.push_back(imageAt(t));
    messages.push_back(imuAt(t));
  }
  ListSource source(messages);
  const std::string out = test::scratchDir() + "/out";
  const RunResult r = runOffline(source, defaultConfig(), quietRun(out));
  EXPECT_EQ(r.resets, 1);
  EXPECT_EQ(r.frames, 41u) << "every image, on either clock, is tracked";
  EXPECT_EQ(r.dropped_images, 0u);
  EXPECT_EQ(r.dropped_imu, 0u);
  EXPECT_NE(test::readFile(out + "/events.log").find("IMU clock jumped back 0.495 s"),
            std::string::npos);
}

TEST(LogThrottle, OneLinePerPeriodCountingWhatItStandsFor) {
  LogThrottle throttle(2.0);
  std::size_t n = 0;
  EXPECT_TRUE(throttle.shouldLog(10.0, &n));
  EXPECT_EQ(n, 1u);
  for (double t = 10.1; t < 11.95; t += 0.1) EXPECT_FALSE(throttle.shouldLog(t, &n));
  EXPECT_TRUE(throttle.shouldLog(12.0, &n));
  EXPECT_EQ(n, 20u);  // the 19 held back and this one
  EXPECT_TRUE(throttle.shouldLog(3.0, &n)) << "time going back starts afresh";
  EXPECT_EQ(throttle.total(), 22u);
}
