// Rosbag-driven regression test: the offline pipeline (runOffline, the code of
// alvio_run) reads the simulated bag through rosbag::View (RosbagSource) and must
// keep its accuracy: ATE RMSE under a committed threshold. It must also be
// deterministic: the same poses as alvio_run produced on the same bag (the test
// data step runs it with --opencv-threads 1, so this in-process run, with OpenCV's worker
// threads, also shows that they leave the result alone). A second run with one IMU sample in
// three NaN or infinite for 1 s while tracking (the faults suite's imu_nan_inf) must drop them
// and go on without a reset. Input: make_test_data.sh (ctest fixture alvio_ros_data).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>

#include "alvio/config/config.h"
#include "alvio/eval/trajectory_evaluation.h"
#include "alvio/io/trajectory_io.h"
#include "alvio/pipeline/offline_runner.h"
#include "rosbag_source.h"
#include "test_support.h"

using namespace alvio;
namespace fs = std::filesystem;

namespace {

// Measured on the first 16 s of the simulated demo sequence (alvio_sim --demo: figure
// eight in the machine hall; config/euroc.yaml, points and lines): ATE RMSE 0.0125 m
// (SE(3) alignment) over 242 poses, 20.0 m of path, since initialisation at 40 px parallax
// (0.0183 m over 229 poses at 80 px). The threshold is 1.3x that. With the anchored point
// tracks (points.anchors, on since the twenty-seventh session): 0.0127 m over 237 poses.
// With new corners sought only once 20 are missing (points.min_new_features, twenty-eighth
// session): 0.0119 m over 239 poses. With the adaptive weights' M counting tracked features
// (estimator.selection.track_measure count, twenty-ninth session): 0.0120 m over 239 poses.
constexpr double kAteThresholdM = 0.0163;

const std::string kData = ALVIO_ROS_TEST_DATA;

std::string unavailable() {
  if (!fs::exists(kData + "/UNAVAILABLE")) return "";
  std::ifstream in(kData + "/UNAVAILABLE");
  std::string why;
  std::getline(in, why);
  return why.empty() ? "unavailable" : why;
}

// Another source's messages, with one IMU sample in three NaN or infinite (both rates) from
// `from_s` to `to_s` after the first message.
class CorruptedImuSource : public SensorSource {
 public:
  CorruptedImuSource(SensorSource& source, double from_s, double to_s)
      : source_(source), from_s_(from_s), to_s_(to_s) {}
  bool next(SensorMessage* m) override {
    if (!source_.next(m)) return false;
    if (first_ns_ < 0) first_ns_ = m->t_ns;
    const double t = (m->t_ns - first_ns_) * 1e-9;
    if (m->kind == SensorMessage::Kind::kImu && t >= from_s_ && t < to_s_ && seen_++ % 3 == 0) {
      const double bad = corrupted_++ % 2 ? std::numeric_limits<double>::infinity()
                                          : std::numeric_limits<double>::quiet_NaN();
      m->imu.gyr.x() = bad;
      m->imu.acc.z() = bad;
    }
    return true;
  }
  std::size_t imageCount() const override { return source_.imageCount(); }
  std::string description() const override { return source_.description() + ", IMU corrupted"; }
  int corrupted() const { return corrupted_; }

 private:
  SensorSource& source_;
  double from_s_, to_s_;
  int64_t first_ns_ = -1;
  int seen_ = 0, corrupted_ = 0;
};

}  // namespace

TEST(RosbagRegression, AccuracyOnTheSimulatedBagStaysUnderTheThreshold) {
  if (const std::string why = unavailable(); !why.empty()) GTEST_SKIP() << "no test data: " << why;
  const Config config = Config::load(test::sourcePath("config/euroc.yaml"));
  RosbagSource source(kData + "/sim.bag", config.topics);
  const std::size_t images = source.imageCount();
  RunOptions options;
  options.out_dir = test::scratchDir();
  options.progress = false;
  const RunResult run = runOffline(source, config, options);

  EXPECT_EQ(run.frames, images);
  EXPECT_EQ(run.resets, 0);
  ASSERT_GT(run.poses, images / 2) << "initialised too late, or lost";
  const Trajectory gt = readTrajectory(kData + "/groundtruth.tum");
  const EvaluationResult e = evaluateTrajectory(run.trajectory, gt, EvaluationOptions());
  std::cout << "ATE RMSE " << e.ate_translation_m.rmse << " m over " << e.matched << " poses, "
            << e.path_length_m << " m of path (threshold " << kAteThresholdM << " m)\n";
  EXPECT_LT(e.ate_translation_m.rmse, kAteThresholdM);

  const Trajectory reference = readTrajectory(kData + "/offline/trajectory.tum");
  ASSERT_EQ(run.trajectory.size(), reference.size()) << "alvio_run on the same bag differs";
  for (std::size_t i = 0; i < reference.size(); ++i) {
    ASSERT_NEAR(run.trajectory[i].t, reference[i].t, 1e-6) << "pose " << i;
    ASSERT_LT((run.trajectory[i].p - reference[i].p).norm(), 1e-6) << "pose " << i;
  }
}

TEST(RosbagRegression, CorruptedImuSamplesWhileTrackingAreDroppedWithoutAReset) {
  if (const std::string why = unavailable(); !why.empty()) GTEST_SKIP() << "no test data: " << why;
  const Config config = Config::load(test::sourcePath("config/euroc.yaml"));
  RosbagSource bag(kData + "/sim.bag", config.topics);
  CorruptedImuSource source(bag, 11.0, 12.0);  // tracking since about 5 s
  RunOptions options;
  options.out_dir = test::scratchDir();
  options.progress = false;
  const RunResult run = runOffline(source, config, options);
  ASSERT_GT(source.corrupted(), 60);
  EXPECT_EQ(run.dropped_imu, static_cast<std::size_t>(source.corrupted()));
  EXPECT_EQ(run.resets, 0);
  ASSERT_GT(run.poses, bag.imageCount() / 2);
  for (const auto& p : run.trajectory) ASSERT_TRUE(p.p.allFinite() && p.q.coeffs().allFinite());
  const EvaluationResult e = evaluateTrajectory(
      run.trajectory, readTrajectory(kData + "/groundtruth.tum"), EvaluationOptions());
  EXPECT_LT(e.ate_translation_m.rmse, kAteThresholdM);
}
